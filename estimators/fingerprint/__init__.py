"""Fingerprint matching components."""

from indoorsim.estimators.fingerprint.knn import WKNN

__all__ = ["WKNN"]
