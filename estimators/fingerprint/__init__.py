"""Fingerprint matching components: WKNN, the DTW family, HV fingerprints, sequence matching."""

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
from indoorsim.estimators.fingerprint.sequences import (
    MagneticSequenceMatcher,
    ReferenceTrack,
    WifiSequenceMatcher,
    distance_along,
    reference_tracks,
    resample_by_distance,
)

__all__ = [
    "DEFAULT_FLOOR_DBM",
    "WKNN",
    "FingerprintLibrary",
    "MagneticSequenceMatcher",
    "ReferenceTrack",
    "SubsequenceMatch",
    "WifiSequenceMatcher",
    "ddtw_many",
    "derivative",
    "distance_along",
    "dtw_distance",
    "dtw_many",
    "hv_components",
    "hv_ddtw_many",
    "match_subsequence",
    "md_dtw_many",
    "reference_tracks",
    "resample_by_distance",
    "weighted_knn",
]
