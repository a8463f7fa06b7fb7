"""The telegram layer's part of vector generation: for now in vectors.py (the first
capability, whose generator became the engine)."""
from ..vectors import observed_requirements, parse_events, to_steps, vectors_for_roles  # noqa: F401
