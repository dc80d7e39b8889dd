"""The model stage: one frozen, format-neutral `Robot` (SI units) and the maths that reads it."""
