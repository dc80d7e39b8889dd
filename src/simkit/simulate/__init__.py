"""The simulate stage: MuJoCo runs on the staged (written) files, returning plain reports."""
