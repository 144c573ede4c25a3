"""Figures (matplotlib, pyvista off-screen). Reads results, never solves; nothing in the
library imports this package."""
