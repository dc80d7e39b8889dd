"""`python -m simkit.cli ARGS`: the same entry as the `simkit` script (tests and scripts
run the CLI this way, as a real subprocess)."""

from simkit.cli import main

if __name__ == "__main__":  # pragma: no cover
    main()
