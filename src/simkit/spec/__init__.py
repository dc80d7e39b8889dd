"""The spec stage: what a person writes (YAML), its schema and its validation."""
