"""Studies over many runs: sweeps (:mod:`.sweep`)."""
