"""Solving one scene with one method: the plugin host and the stage pipeline."""
