"""The simulated pedestrian: routes through the walkable area, gait, and how the phone is carried."""
