"""Wall materials: radio attenuation per crossing and light transmittance.

Radio losses follow REALISM.md §4.2: the WiFi-planner rule-of-thumb constants at
2.4 GHz (drywall 3, wood 4, glass 2, brick 8, concrete 12, metal 20 dB) and
3GPP TR 38.901 Table 7.4.3-1 for the growth toward 5 GHz (concrete 5 + 4f dB,
standard glass 2 + 0.2f dB, wood 4.85 + 0.12f dB). Between the two tabulated
frequencies the loss is interpolated linearly in frequency.

Light transmittance is the fraction of the direct illuminance that passes the
element: opaque walls 0, clear glazing about 0.8 (a normal float-glass pane).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, kw_only=True)
class Material:
    """Physical properties of one wall material.

    Attributes:
        name: registry key.
        loss_2g4_db: radio attenuation of one crossing at 2.4 GHz, dB.
        loss_5g_db: radio attenuation of one crossing at 5.2 GHz, dB.
        light_transmittance: fraction of direct light passing through (0 = opaque).
    """

    name: str
    loss_2g4_db: float
    loss_5g_db: float
    light_transmittance: float

    def loss_db(self, frequency_ghz: float) -> float:
        """Attenuation of one crossing at ``frequency_ghz``, linear in frequency."""
        f0, f1 = 2.4, 5.2
        w = (frequency_ghz - f0) / (f1 - f0)
        return self.loss_2g4_db + w * (self.loss_5g_db - self.loss_2g4_db)


MATERIALS: dict[str, Material] = {
    m.name: m
    for m in (
        Material(name="concrete", loss_2g4_db=12.0, loss_5g_db=25.8, light_transmittance=0.0),
        Material(name="brick", loss_2g4_db=8.0, loss_5g_db=10.0, light_transmittance=0.0),
        Material(name="drywall", loss_2g4_db=3.0, loss_5g_db=4.5, light_transmittance=0.0),
        Material(name="glass", loss_2g4_db=2.0, loss_5g_db=3.0, light_transmittance=0.8),
        Material(name="wood", loss_2g4_db=4.0, loss_5g_db=5.5, light_transmittance=0.0),
        Material(name="metal", loss_2g4_db=20.0, loss_5g_db=26.0, light_transmittance=0.0),
        Material(name="metal_door", loss_2g4_db=20.0, loss_5g_db=26.0, light_transmittance=0.0),
    )
}
