"""Numbers about results: exact reference values of a scene, metrics, result collections and
reference curves."""
