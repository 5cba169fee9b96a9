"""seisrack.validation: the paper's validation examples (issue #3)."""
