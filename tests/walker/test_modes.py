"""The carrying-mode registry: built-in modes, registration, plug-ins from entry points."""

from __future__ import annotations

import dataclasses
import pickle
from importlib.metadata import EntryPoint
from typing import ClassVar

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import indoorsim.walker.modes as modes_module
from indoorsim.walker.carry import Handheld, carry
from indoorsim.walker.gait import BodyTrajectory
from indoorsim.walker.modes import (
    ENTRY_POINT_GROUP,
    MODES,
    CarryMode,
    ModePose,
    UnknownModeError,
    available_modes,
    get_mode,
    register_mode,
)

BUILT_IN = ("handheld", "calling", "dangling", "pocketed")


@dataclasses.dataclass(kw_only=True, frozen=True)
class StrappedMode(CarryMode):
    """A test plugin: the phone strapped flat to the pelvis, top forward."""

    name: ClassVar[str] = "strapped"

    def pose(self, body: BodyTrajectory, rng: np.random.Generator) -> ModePose:
        rot = Rotation.from_rotvec(np.outer(body.heading - np.pi / 2, [0.0, 0.0, 1.0]))
        return ModePose(pos=body.pos.copy(), rot=rot, light_exposure=np.ones(len(body.t)))


def test_built_in_modes_are_registered():
    assert set(BUILT_IN) <= set(MODES)
    assert set(BUILT_IN) <= set(available_modes())
    assert get_mode("handheld") is Handheld
    with pytest.raises(KeyError) as err:
        get_mode("backpack")
    for name in BUILT_IN:
        assert name in str(err.value)


def test_an_unknown_mode_is_a_lookup_error_listing_the_valid_names():
    with pytest.raises(UnknownModeError) as info:
        get_mode("backpack")
    err = info.value
    assert isinstance(err, LookupError) and isinstance(err, KeyError)
    assert isinstance(err, ValueError)  # as the env and the evaluation raised before
    assert (err.name, err.valid) == ("backpack", tuple(available_modes()))
    assert str(err) == (
        "unknown carrying mode 'backpack'; valid carrying modes are: "
        + ", ".join(available_modes())
    )
    again = pickle.loads(pickle.dumps(err))
    assert (type(again), str(again)) == (UnknownModeError, str(err))


def test_register_mode_refuses_clashes_and_non_modes():
    with pytest.raises(TypeError):
        register_mode(dict)  # type: ignore[arg-type]

    @dataclasses.dataclass(kw_only=True, frozen=True)
    class Impostor(StrappedMode):
        name: ClassVar[str] = "handheld"

    with pytest.raises(ValueError, match="already registered"):
        register_mode(Impostor)


def test_a_plugin_mode_loads_from_its_entry_point(monkeypatch, straight_body):
    ep = EntryPoint(
        name="strapped", value="tests.walker.test_modes:StrappedMode", group=ENTRY_POINT_GROUP
    )
    monkeypatch.setattr(modes_module, "MODES", dict(MODES))
    monkeypatch.setattr(
        modes_module, "entry_points", lambda group: [ep] if group == ENTRY_POINT_GROUP else []
    )
    assert "strapped" in available_modes()
    assert get_mode("strapped") is StrappedMode
    phone = carry(straight_body, "strapped", np.random.default_rng(0))
    assert set(phone.mode) == {"strapped"}
    np.testing.assert_allclose(phone.pos, straight_body.pos)


def test_an_entry_point_that_is_not_a_mode_is_refused(monkeypatch):
    ep = EntryPoint(name="bogus", value="indoorsim.walker.gait:walk", group=ENTRY_POINT_GROUP)
    monkeypatch.setattr(modes_module, "MODES", dict(MODES))
    monkeypatch.setattr(modes_module, "entry_points", lambda group: [ep])
    with pytest.raises(TypeError, match="bogus"):
        get_mode("bogus")


def test_old_import_paths_of_the_registry_still_work():
    import indoorsim.walker.carry as carry_module

    for name in ("ENTRY_POINT_GROUP", "MODES", "CarryMode", "ModePose", "get_mode"):
        assert getattr(carry_module, name) is getattr(modes_module, name)
