"""Top-down mission layer: events, decomposition by natural projection, separability,
assume-guarantee verification."""
