"""The simulate stage: runs MuJoCo on the staged (written) kit files and returns plain reports."""
