"""simkit: one YAML spec per robot in, a complete and checked simulation kit out."""

__version__ = "0.1.0"

__all__ = ["__version__"]
