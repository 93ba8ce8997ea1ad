"""Gymnasium environments for indoor positioning (DESIGN §9)."""
