"""The repository's promises: the shape of the code (architecture, one definition of every
option), README and CI in sync, the documented examples, the public API, benchmarks that run."""
