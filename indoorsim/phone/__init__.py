"""The simulated phone: device profiles, sensor error models and Android-style fused sensors."""
