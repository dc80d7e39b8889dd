"""Independent readers for the kit's binary formats (USD, GLB)."""
