"""Rough profiles and surfaces: the data type, generators, readers and statistics."""
from .surface import Surface

__all__ = ["Surface"]
