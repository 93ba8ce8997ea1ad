"""Position estimators: the protocol, reusable components, the paper pipelines and baselines."""
