"""Industrial applications of an identified parameter set."""
