"""Gaits the package no longer ships (docs/HISTORY.md, "Retired gaits and objectives"), kept where a test needs
their properties: `load_gait(STEADY)`."""

from pathlib import Path

# The first default gait: a saddle orbit on Drake's default contact, gains inside every paper mutation's bounds,
# and no climber of 0.02 rad.
STEADY = Path(__file__).parent / "gaits" / "steady.json"
