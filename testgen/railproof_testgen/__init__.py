"""railproof testgen: specification checks, SPIN runs, vector generation, traceability."""
__version__ = "0.1.0"
