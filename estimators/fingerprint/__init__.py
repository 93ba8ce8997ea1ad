"""Fingerprint matching components: WKNN, the DTW family, HV fingerprints."""

from indoorsim.estimators.fingerprint.dtw import (
    DEFAULT_FLOOR_DBM,
    SubsequenceMatch,
    ddtw_many,
    dtw_distance,
    dtw_many,
    hv_ddtw_many,
    match_subsequence,
    md_dtw_many,
    weighted_knn,
)
from indoorsim.estimators.fingerprint.hv import derivative, hv_components
from indoorsim.estimators.fingerprint.knn import WKNN
from indoorsim.estimators.fingerprint.library import FingerprintLibrary

__all__ = [
    "DEFAULT_FLOOR_DBM",
    "WKNN",
    "FingerprintLibrary",
    "SubsequenceMatch",
    "ddtw_many",
    "derivative",
    "dtw_distance",
    "dtw_many",
    "hv_components",
    "hv_ddtw_many",
    "match_subsequence",
    "md_dtw_many",
    "weighted_knn",
]
