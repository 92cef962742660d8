"""The README's minimal plugin works as written and passes the conformance kit."""
import re
import types
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_plugin_example_passes_conformance(railtherm_register):
    text = README.read_text()
    code = re.search(r"```python\n(# my_plugin/plugin.py\n.*?)```", text, re.S).group(1)
    mod = types.ModuleType("my_plugin_plugin")
    exec(compile(code, "README-plugin", "exec"), mod.__dict__)
    railtherm_register("crude", mod)
    from railtherm.testing import check_method
    outcome = check_method("crude")
    assert outcome["ellipse-full-sliding"] == "ok"
    assert outcome["line-full-sliding"] == "ok"


def test_readme_starts_with_the_two_commands():
    text = README.read_text()
    blocks = re.findall(r"```bash\n(.*?)```", text, re.S)
    assert "railtherm run studies/seed_paper.toml" in blocks[0]
    assert "python -m pytest" in blocks[1]
    ci = (README.parent / ".ci" / "run").read_text()
    assert "python -m pytest\n" in ci
