"""Small shared helpers with no knowledge of the simulation: quaternions, seeding, kernels."""
