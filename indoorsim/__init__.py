"""indoorsim: a simulation-and-benchmark suite for smartphone indoor positioning."""
