"""Studies built on the toolkit: the line study (:mod:`pinarms.studies.line`)."""

__all__ = ["line"]
