"""Paper pipelines assembled from the components of :mod:`indoorsim.estimators`.

Importing a pipeline module registers its estimators (:func:`~indoorsim.estimators.base.register`).
"""
