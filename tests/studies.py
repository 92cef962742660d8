"""TOML pieces the tests' small studies share: the steel of wheel and rail, and the sliding ellipse of
Knothe's example (100 kN, 30 m/s, 1 m/s sliding, friction 0.3), so that each test's study text holds only
what that test is about."""

ELLIPSE_AXES = "semi_axes = [5.88e-3, 10.54e-3]"      # [m]: the ellipse given by its semi-axes
ELLIPSE_CURVATURES = "curvatures = [1.015, 0.4215]"  # [m-1]: the same ellipse by the bodies' curvatures


def steel(side: str, *, poisson: bool = True, thermal: bool = False, bulk_temperature: float | None = None) -> str:
    """The ``[defaults.<side>]`` table of steel: shear modulus 82 GPa [Pa], with Poisson's ratio 0.28 [-] when
    ``poisson``, density 7850 [kg m-3], specific heat 450 [J kg-1 K-1] and conductivity 50 [W m-1 K-1] when
    ``thermal``, and the bulk temperature [degC] when given."""
    lines = [f"[defaults.{side}]", "shear_modulus = 82e9"]
    if poisson:
        lines.append("poisson_ratio = 0.28")
    if thermal:
        lines += ["density = 7850.0", "specific_heat = 450.0", "conductivity = 50.0"]
    if bulk_temperature is not None:
        lines.append(f"bulk_temperature = {bulk_temperature}")
    return "\n".join(lines) + "\n"


# the elastic pair most studies use: the rail takes core's default Poisson's ratio
ELASTIC = steel("wheel") + steel("rail", poisson=False)


def ellipse_scene(name: str = "ek", *, contact: str = ELLIPSE_AXES, speed: str = "30.0") -> str:
    """A ``[[scene]]`` of an ellipse (``contact``: ``ELLIPSE_AXES`` or ``ELLIPSE_CURVATURES``) under 100 kN
    [N] at ``speed`` [m s-1] (TOML text: one value or a list) sliding at 1 m/s with friction 0.3; the caller
    appends the scene's further keys."""
    return (f'[[scene]]\nname = "{name}"\nnormal_force = 100e3\ncontact = {{ shape = "ellipse", {contact} }}\n'
            f"speed = {speed}\nsliding_speed = 1.0\nfriction = 0.3\n")


def green_analytic_study(name: str) -> str:
    """The head of a small study: green at level 0 against the analytic references (5 %), no convection; the
    caller appends its ``[[scene]]`` tables."""
    return (f'schema_version = 1\n[study]\nname = "{name}"\nmethods = ["green"]\nlevels = [0]\n'
            'reference = "analytic"\ntolerance = 0.05\n[defaults]\nconvection = 0.0\n')


def run_with_report(folder, text: str):
    """Run the study of TOML ``text`` in ``folder`` (a path) without its report, then write the report once:
    ``(study, out, paths)``, the parsed study, its output folder and the report's paths."""
    import railtherm                        # here: the report's plotting only for the tests that draw one
    from railtherm.report import write_report
    path = folder / "study.toml"
    path.write_text(text)
    study = railtherm.load_study(path)
    out = folder / "out"
    railtherm.run_study(study, out=out, report=False)
    return study, out, write_report(out, study)
