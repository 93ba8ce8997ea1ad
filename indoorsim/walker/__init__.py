"""The simulated pedestrian: routes, gait, and how the phone is carried."""
