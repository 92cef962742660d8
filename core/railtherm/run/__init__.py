"""Running a study: the runner, its executors and time limits."""
