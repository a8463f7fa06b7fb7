"""Each capability's part of vector generation, by the registry's short name
(spec/capabilities.yaml): capabilities/<name>.py. The engine (vectors.py) is generic."""
