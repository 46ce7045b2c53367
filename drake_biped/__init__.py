"""drake-biped: a CPG-driven 7-link biped in Drake that learns a torque-free hip period (GARB)."""

__version__ = "0.1.0"
