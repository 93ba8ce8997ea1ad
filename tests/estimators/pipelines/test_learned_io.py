"""``learned-io`` and ``indoorsim train``: training, weights-only checkpoints, the estimator."""

from __future__ import annotations

import hashlib
import io
import json
import math
import pickle
from pathlib import Path

import numpy as np
import pytest
import torch

import indoorsim
from indoorsim.benchmark.evaluation import (
    check_estimator,
    run_episode,
    start_info,
    true_positions_at,
)
from indoorsim.cli import main
from indoorsim.dataset import DatasetConfig, build_dataset
from indoorsim.dataset.torch import WindowDataset
from indoorsim.dataset.train import TRAINING_STATE, TrainConfig, TrainingFolderError, train
from indoorsim.estimators.base import SiteContext, StartInfo, make
from indoorsim.estimators.nn.inertial import (
    MODEL_JSON,
    WEIGHTS_FILE,
    Checkpoint,
    CheckpointError,
    InertialConfig,
    InertialResNet,
    load_checkpoint,
    weights_bytes,
)
from indoorsim.estimators.pipelines.learned_io import LearnedIO
from indoorsim.simulate import simulate
from indoorsim.util import quaternion
from indoorsim.windows import PRESENT_ORDER

# Two small sites (the bundled 10 m room and a generated hall), one minute each,
# the IMU at 50 Hz in 1 s windows every 0.5 s: ~230 windows, seconds to build.
TINY = DatasetConfig(
    sites=2,
    walks_per_site=1,
    minutes=1.0,
    seed=3,
    bundled=["minimal_room"],
    bundled_share=0.5,
    generated_kinds=["open_hall"],
    imu_rate_hz=50.0,
    window_samples=50,
    stride_samples=25,
    rows_per_row_group=64,
)
EPOCHS, BATCH = 10, 32

# The tiny data set has two sites, so its val and test splits are empty: train says so.
pytestmark = pytest.mark.filterwarnings("ignore:--data .* split holds no windows:UserWarning")


@pytest.fixture(scope="module")
def tiny_data(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("tiny") / "data"
    build_dataset(TINY, out, workers=1, progress=False)
    return out


@pytest.fixture(scope="module")
def tiny_checkpoint(tiny_data: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A checkpoint trained by the command line on the tiny data set."""
    out = tmp_path_factory.mktemp("ckpt") / "io"
    argv = ["train", "--data", str(tiny_data), "--out", str(out), "--epochs", str(EPOCHS)]
    assert main([*argv, "--batch-size", str(BATCH), "--quiet"]) == 0
    return out


def _mse(model: torch.nn.Module, data: Path) -> float:
    ds = WindowDataset(data, frame="world")
    imu = torch.stack([ds[i]["imu"] for i in range(len(ds))])
    vel = torch.stack([ds[i]["vel"] for i in range(len(ds))])
    with torch.inference_mode():
        return float(((model.eval()(imu) - vel) ** 2).mean())


def test_tiny_training_run_lowers_the_loss(tiny_data, tiny_checkpoint):
    meta = json.loads((tiny_checkpoint / MODEL_JSON).read_text())
    # Finished: the two files a user needs, no optimiser state left behind.
    assert sorted(p.name for p in tiny_checkpoint.iterdir()) == [MODEL_JSON, WEIGHTS_FILE]
    assert meta["complete"] and meta["epochs_done"] == EPOCHS == len(meta["history"])
    assert meta["imu_rate_hz"] == 50.0 and meta["window_samples"] == 50
    card = (tiny_data / "dataset_card.json").read_bytes()
    assert meta["data"]["card_sha256"] == hashlib.sha256(card).hexdigest()
    # The same network before training (same seed) against after, on the same windows.
    torch.manual_seed(0)
    untrained = InertialResNet(InertialConfig(), meta["input_mean"], meta["input_std"])
    trained = load_checkpoint(tiny_checkpoint).model
    assert _mse(trained, tiny_data) < 0.5 * _mse(untrained, tiny_data)
    losses = [h["train_loss"] for h in meta["history"]]
    assert losses[-1] < losses[0]


def test_interrupted_training_resumes_to_the_same_weights(
    tiny_data, tiny_checkpoint, tmp_path, monkeypatch
):
    from indoorsim.dataset import train as training

    out = tmp_path / "io"
    config = TrainConfig(epochs=EPOCHS, batch_size=BATCH)
    write = training._write_checkpoint
    written = []

    def interrupt_after_three(*args, **kwargs):
        write(*args, **kwargs)
        written.append(1)
        if len(written) == 3:
            raise KeyboardInterrupt

    monkeypatch.setattr(training, "_write_checkpoint", interrupt_after_three)
    with pytest.raises(KeyboardInterrupt):
        train(tiny_data, out, config, progress=False)
    assert (out / TRAINING_STATE).is_file()
    assert json.loads((out / MODEL_JSON).read_text())["epochs_done"] == 3
    monkeypatch.setattr(training, "_write_checkpoint", write)

    with pytest.raises(TrainingFolderError, match="another run"):
        train(tiny_data, out, TrainConfig(epochs=EPOCHS, batch_size=BATCH, lr=1e-3))
    report = train(tiny_data, out, config, progress=False)
    assert (report.resumed_from, report.epochs_run) == (3, EPOCHS - 3)
    # Seeded per epoch and deterministic: the same bytes as the uninterrupted run.
    assert (out / WEIGHTS_FILE).read_bytes() == (tiny_checkpoint / WEIGHTS_FILE).read_bytes()
    assert not (out / TRAINING_STATE).exists()
    assert train(tiny_data, out, config, progress=False).epochs_run == 0


def test_checkpoint_round_trip_gives_identical_predictions(tiny_checkpoint, tmp_path):
    first = load_checkpoint(tiny_checkpoint)
    copy = tmp_path / "copy"
    copy.mkdir()
    (copy / WEIGHTS_FILE).write_bytes(weights_bytes(first.model))
    (copy / MODEL_JSON).write_bytes((tiny_checkpoint / MODEL_JSON).read_bytes())
    second = load_checkpoint(copy)
    # Saving what was loaded gives the same bytes: nothing is lost or added.
    assert (copy / WEIGHTS_FILE).read_bytes() == (tiny_checkpoint / WEIGHTS_FILE).read_bytes()
    imu = torch.randn(16, 6, first.window_samples, generator=torch.Generator().manual_seed(1))
    imu[:, 2] += 9.81
    with torch.inference_mode():
        assert torch.equal(first.model(imu), second.model(imu))


# Set if unpickling ever calls the payload's constructor: it must stay empty.
SPRUNG: list[str] = []


def _spring(text: str) -> str:
    SPRUNG.append(text)
    return text


class _Trap:
    """Unpickles by calling a function: what a malicious checkpoint would do."""

    def __reduce__(self):
        return (_spring, ("code ran",))


def _payloads(state: dict[str, torch.Tensor]) -> dict[str, bytes]:
    def saved(obj: object) -> bytes:
        buf = io.BytesIO()
        torch.save(obj, buf)
        return buf.getvalue()

    name = next(iter(state))
    return {
        "object_in_state_dict": saved(state | {name: _Trap()}),
        "plain_pickle": pickle.dumps({name: _Trap()}, protocol=2),
        "string_in_state_dict": saved(state | {name: "not a tensor"}),
        "list_of_tensors": saved(list(state.values())),
    }


@pytest.mark.parametrize(
    "payload",
    ["object_in_state_dict", "plain_pickle", "string_in_state_dict", "list_of_tensors"],
)
def test_weights_with_anything_but_tensors_are_refused(tiny_checkpoint, tmp_path, payload):
    state = load_checkpoint(tiny_checkpoint).model.state_dict()
    data = _payloads(state)[payload]
    bad = tmp_path / "bad"
    bad.mkdir()
    (bad / WEIGHTS_FILE).write_bytes(data)
    # Whoever crafted the weights can fix the checksum too: refusal must not rest on it.
    meta = json.loads((tiny_checkpoint / MODEL_JSON).read_text())
    meta["weights_sha256"] = hashlib.sha256(data).hexdigest()
    (bad / MODEL_JSON).write_text(json.dumps(meta))
    with pytest.raises(CheckpointError, match="refused"):
        load_checkpoint(bad)
    assert SPRUNG == []
    with pytest.raises(CheckpointError, match="refused"):
        make("learned-io", checkpoint=str(bad)).fit(_context(50.0, 50), [])


def test_weights_changed_behind_model_json_are_refused(tiny_checkpoint, tmp_path):
    state = load_checkpoint(tiny_checkpoint).model.state_dict()
    state["head.bias"] = state["head.bias"] + 1.0
    folder = tmp_path / "changed"
    folder.mkdir()
    buf = io.BytesIO()
    torch.save(state, buf)
    (folder / WEIGHTS_FILE).write_bytes(buf.getvalue())
    (folder / MODEL_JSON).write_bytes((tiny_checkpoint / MODEL_JSON).read_bytes())
    with pytest.raises(CheckpointError, match="SHA-256"):
        load_checkpoint(folder)


def test_check_estimator_passes():
    check_estimator("learned-io")


def _context(rate_hz: float, window_samples: int, site: object = None) -> SiteContext:
    if site is None:
        return SiteContext(name="stub", imu_rate_hz=rate_hz, window_samples=window_samples)
    return SiteContext(
        name=site.name,
        building_north_deg=site.scenario.site.north_deg,
        magnetic_declination_deg=site.magnetic_declination_deg,
        imu_rate_hz=rate_hz,
        window_samples=window_samples,
    )


@pytest.mark.parametrize(
    ("mode", "device", "rate_hz"),
    [
        ("handheld", "nexus_5x", 50.0),
        ("calling", "nexus_5x", 50.0),
        ("dangling", "nexus_5x", 50.0),
        ("pocketed", "nexus_5x", 50.0),
        ("handheld", "mid_grade", 100.0),
        ("dangling", "high_grade", 200.0),
    ],
)
def test_packaged_network_tracks_the_walk_in_every_mode_and_rate(mode, device, rate_hz):
    """The packaged checkpoint (50 Hz) on a bundled room it never saw, 1 s windows."""
    site = indoorsim.load_site("minimal_room")
    rec = simulate(site, route="main", mode=mode, device=device, seed=1)
    ctx = _context(rate_hz, int(rate_hz), site)
    est = make("learned-io")
    est.fit(ctx, [])
    start = start_info(rec)
    res = run_episode(est, rec, ctx, start)
    truth = true_positions_at(rec, res.t)
    error = np.linalg.norm(res.estimate - truth, axis=1).mean()
    standing = np.linalg.norm(truth - start.position, axis=1).mean()
    # Far better than not moving: the speed and direction are learned, not guessed.
    assert error < 0.5 * standing
    assert np.isfinite(res.heading).all()


def _stub(model_rate_hz: float, window_samples: int, frame: str = "world") -> LearnedIO:
    torch.manual_seed(0)
    meta = {"frame": frame, "imu_rate_hz": model_rate_hz, "window_samples": window_samples}
    est = LearnedIO()
    est._net = Checkpoint(model=InertialResNet().eval(), meta=meta)
    return est


def _obs(t: np.ndarray, accel: np.ndarray, gyro: np.ndarray, rotation: np.ndarray) -> dict:
    n = len(t)
    return {
        "t": t,
        "valid": np.ones(n, np.int8),
        "accel": accel,
        "gyro": gyro,
        "rotation": rotation,
        "game_rotation": rotation,
        "gravity": np.zeros((n, 3)),
        "present": np.ones(len(PRESENT_ORDER), np.int8),
    }


@pytest.mark.parametrize(("device_hz", "model_hz"), [(200.0, 50.0), (50.0, 100.0)])
def test_resampling_reproduces_a_linear_signal_at_the_model_rate(device_hz, model_hz):
    """Linear interpolation is exact on a ramp, whatever the phone's jittered clock."""
    window = int(device_hz)  # 1 s observation windows
    est = _stub(model_hz, window_samples=int(3 * model_hz))
    est._resample = True  # what fit() decides for a phone at another rate
    est.reset(StartInfo(position=np.zeros(2), heading=0.0, t0=0.0))
    rng = np.random.default_rng(0)
    n = 4 * window
    t = np.arange(n) / device_hz + rng.uniform(-0.2, 0.2, n) / device_hz
    t[0] = 0.0
    # The phone turned by 90° about z: the world-frame signal is what must be resampled.
    turn = np.array([math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4)])
    world = np.column_stack([2.0 * t, 1.0 - t, 9.81 + 0 * t, 0.1 * t, 0 * t, -0.5 * t])
    phone_acc = quaternion.rotate(quaternion.conjugate(turn), world[:, :3])
    phone_gyro = quaternion.rotate(quaternion.conjugate(turn), world[:, 3:])
    rot = np.broadcast_to(turn, (n, 4)).copy()
    for k in range(4):
        s = slice(k * window, (k + 1) * window)
        est.act(_obs(t[s], phone_acc[s], phone_gyro[s], rot[s]))
    grid = np.arange(math.floor(t[-1] * model_hz + 1e-9) + 1) / model_hz
    expected = np.column_stack(
        [2.0 * grid, 1.0 - grid, 9.81 + 0 * grid, 0.1 * grid, 0 * grid, -0.5 * grid]
    )[-est._net.window_samples :]
    np.testing.assert_allclose(est._buffer, expected, atol=1e-9)


@pytest.mark.parametrize(
    ("frame", "missing"), [("world", "rotation"), ("gravity_aligned", "game_rotation")]
)
def test_without_its_attitude_stream_the_position_holds(frame: str, missing: str):
    est = _stub(50.0, 50, frame)
    est._to_building = 0.0
    est.reset(StartInfo(position=np.array([1.0, 2.0]), heading=0.5, t0=0.0))
    t = np.arange(50) / 50.0
    still = np.tile([0.0, 0.0, 9.81], (50, 1))
    obs = _obs(t, still, np.zeros((50, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (50, 1)))
    obs["present"][PRESENT_ORDER.index(missing)] = 0
    for k in range(3):
        obs["t"] = t + k
        np.testing.assert_array_equal(est.act(obs), [1.0, 2.0])
    assert est.heading == 0.5 and len(est._buffer) == 0


def test_game_rotation_yaw_offset_is_recovered():
    """rotation = yaw(α) ⊗ game_rotation: the game frame's velocity turns by α to the world."""
    rng = np.random.default_rng(2)
    game = rng.normal(size=(40, 4))
    game /= np.linalg.norm(game, axis=1, keepdims=True)
    alpha = 2.5
    yaw = np.array([math.cos(alpha / 2), 0.0, 0.0, math.sin(alpha / 2)])
    obs = {"rotation": quaternion.multiply(yaw, game), "game_rotation": game}
    got = LearnedIO._game_to_world_yaw(obs, np.ones(40, bool))
    assert got == pytest.approx(alpha)


def test_gravity_aligned_training_runs_through_the_estimator(tiny_data, tmp_path):
    out = tmp_path / "ga"
    report = train(tiny_data, out, TrainConfig(epochs=2, frame="gravity_aligned"), progress=False)
    assert report.history[-1]["train_loss"] > 0
    site = indoorsim.load_site("minimal_room")
    rec = simulate(site, route="main", mode="handheld", device="nexus_5x", seed=2)
    ctx = _context(50.0, 50, site)
    est = make("learned-io", checkpoint=str(out))
    est.fit(ctx, [])
    res = run_episode(est, rec, ctx, start_info(rec))
    assert np.isfinite(res.estimate).all()
    assert not np.allclose(res.estimate, res.estimate[0])


def test_train_command_rejects_a_phone_frame_and_missing_data(tmp_path, capsys):
    out = ["--out", str(tmp_path / "o")]
    assert main(["train", "--data", str(tmp_path), *out, "--frame", "phone"]) == 2
    assert "invalid choice" in capsys.readouterr().err
    assert main(["train", "--data", str(tmp_path / "none"), *out]) == 2
    assert "not a folder" in capsys.readouterr().err
    assert main(["train", "--data", str(tmp_path), *out]) == 2
    assert "dataset_card.json" in capsys.readouterr().err


def _yaw(angle: np.ndarray) -> np.ndarray:
    return np.column_stack([np.cos(angle / 2), 0 * angle, 0 * angle, np.sin(angle / 2)])


# A phone tilted 30° about an oblique axis of its own: the yaw is read through the tilt.
_TILT = np.array(
    [math.cos(math.pi / 12), 0.6 * math.sin(math.pi / 12), 0.8 * math.sin(math.pi / 12), 0.0]
)


def _held(tau_s: float | None) -> LearnedIO:
    est = LearnedIO(magnetic_tau_s=tau_s)
    est.reset(StartInfo(position=np.zeros(2), heading=0.0, t0=0.0))
    return est


def _disturbances(est: LearnedIO, t, rotation, gyro, window: int = 50) -> list[float]:
    out = []
    for k in range(0, len(t), window):
        s = slice(k, k + window)
        obs = _obs(t[s], np.zeros((len(t[s]), 3)), gyro[s], rotation[s])
        out.append(est._magnetic_disturbance(obs, np.ones(len(t[s]), bool)))
    return out


def test_a_magnetic_pull_on_the_rotation_vector_is_told_from_a_turn():
    """The fused yaw bumps by 15° for 3 s while the gyro feels nothing: the whole bump
    is disturbance. A real turn at 40°/s, felt by the gyro through the tilt, is none."""
    t = np.arange(500) / 50.0
    bump = np.where((t >= 3.0) & (t < 6.0), math.radians(15.0), 0.0)
    still = _disturbances(_held(1e9), t, quaternion.multiply(_yaw(bump), _TILT), np.zeros((500, 3)))
    expected = np.zeros(10)
    expected[3:6] = math.radians(15.0)
    np.testing.assert_allclose(still, expected, atol=1e-8)

    rate = math.radians(40.0)
    rotation = quaternion.multiply(_yaw(rate * t), _TILT)
    gyro = quaternion.rotate(rotation, np.tile([0.0, 0.0, rate], (500, 1)), inverse=True)
    turning = _disturbances(_held(1e9), t, rotation, gyro)
    np.testing.assert_allclose(turning, 0.0, atol=1e-9)


def test_gyro_drift_is_pulled_back_with_the_time_constant():
    """A gyro biased by b about the vertical, a steady rotation vector: the held heading
    lags the ramp as a first-order filter does, pulled once per 1 s window:
    b·T/(e^{T/τ} − 1) ≈ b·τ, never more."""
    bias, tau = math.radians(0.5), 20.0
    t = np.arange(200 * 50) / 50.0
    rotation = np.tile(_TILT, (len(t), 1))
    gyro = quaternion.rotate(rotation, np.tile([0.0, 0.0, bias], (len(t), 1)), inverse=True)
    lag = _disturbances(_held(tau), t, rotation, gyro)
    assert lag[-1] == pytest.approx(-bias / math.expm1(1.0 / tau), rel=1e-3)
    assert max(abs(v) for v in lag) <= bias * tau


def test_magnetic_time_constant_must_be_positive():
    with pytest.raises(ValueError, match="magnetic_tau_s"):
        LearnedIO(magnetic_tau_s=0.0)


def test_a_turn_inside_a_gap_is_not_taken_for_a_magnetic_pull():
    """The phone turns 90° while its samples are missing for 2 s: after the gap the gyro's
    carry restarts from the rotation vector, so no disturbance appears."""
    t = np.r_[np.arange(0.0, 4.0, 0.02), np.arange(6.0, 10.0, 0.02)]
    yaw = np.where(t < 5.0, 0.0, np.pi / 2)
    rotation = quaternion.multiply(_yaw(yaw), _TILT)
    out = _disturbances(_held(1e9), t, rotation, np.zeros((len(t), 3)))
    np.testing.assert_allclose(out, 0.0, atol=1e-9)


class _MeanPush(torch.nn.Module):
    """A stand-in network that turns with its input: the window's mean horizontal
    specific force, as a velocity."""

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return x[:, 0:2, :].mean(dim=-1)


@pytest.mark.parametrize(("tau_s", "gyro_present"), [(None, True), (1e9, True), (1e9, False)])
def test_the_held_heading_ignores_a_pull_on_the_rotation_vector(tau_s, gyro_present):
    """A still, level phone pushed toward its top; its rotation vector's yaw is pulled
    15° for 3 s while its gyro reads nothing. Following the rotation vector, the
    heading turns with the pull; held on the gyro it does not (unless there is no
    gyro to hold it with)."""
    est = LearnedIO(magnetic_tau_s=tau_s)
    est._net = Checkpoint(
        model=_MeanPush(), meta={"frame": "world", "imu_rate_hz": 50.0, "window_samples": 50}
    )
    est.reset(StartInfo(position=np.zeros(2), heading=0.0, t0=0.0))
    t = np.arange(500) / 50.0
    pull = np.where((t >= 4.0) & (t < 7.0), math.radians(15.0), 0.0)
    rotation = _yaw(pull)
    push = np.tile([0.0, 1.0, 9.81], (500, 1))
    headings = []
    for k in range(0, 500, 50):
        s = slice(k, k + 50)
        obs = _obs(t[s], push[s], np.zeros((50, 3)), rotation[s])
        obs["present"][PRESENT_ORDER.index("gyro")] = int(gyro_present)
        est.act(obs)
        headings.append(est.heading)
    turned = np.degrees(np.array(headings) - headings[0])
    held = tau_s is not None and gyro_present
    np.testing.assert_allclose(turned[[4, 5, 6]], 0.0 if held else 15.0, atol=1e-4)
    np.testing.assert_allclose(turned[[2, 3, 7, 8, 9]], 0.0, atol=1e-4)


START = np.array([5.0, -3.0])


def _aligning(**params) -> LearnedIO:
    est = LearnedIO(frame_offset="start", **params)
    est._net = Checkpoint(
        model=_MeanPush(), meta={"frame": "world", "imu_rate_hz": 50.0, "window_samples": 50}
    )
    est.reset(StartInfo(position=START.copy(), heading=0.0, t0=0.0))
    return est


def _fidget_then_walk(est: LearnedIO, second=(0.0, 1.0)) -> list[tuple[np.ndarray, float]]:
    """One 1 s window of a standing phone read as 0.3 m/s toward 60°, then three of
    walking at 1 m/s, the first toward +y and the others toward ``second``, level and
    unturned; what the estimator returns, and its heading, after each."""
    t = np.arange(200) / 50.0
    fidget = 0.3 * np.array([math.cos(math.pi / 3), math.sin(math.pi / 3)])
    push = np.tile([0.0, 1.0, 9.81], (200, 1))
    push[:50, :2] = fidget
    push[100:, :2] = second
    out = []
    for k in range(0, 200, 50):
        s = slice(k, k + 50)
        position = est.act(_obs(t[s], push[s], np.zeros((50, 3)), _yaw(np.zeros(50))))
        out.append((position, est.heading))
    return out


def _turned(vector: np.ndarray, degrees: float) -> np.ndarray:
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    return np.array([c * vector[0] - s * vector[1], s * vector[0] + c * vector[1]])


def test_the_start_heading_is_set_by_the_way_first_walked_not_by_a_fidget():
    # The fidget (0.3 m/s) is under walking speed: it does not count. The way first
    # walked is 1 m toward +y and then 1 m toward +x: 1.41 m toward 45°, turned onto the
    # start heading (+x) by −45°, and so is everything walked since the start, about
    # the start. Until then the estimate holds the start.
    steps = _fidget_then_walk(_aligning(align_distance_m=1.4), second=(1.0, 0.0))
    fidget = 0.3 * 0.98 * np.array([math.cos(math.pi / 3), math.sin(math.pi / 3)])
    for position, heading in steps[:2]:
        np.testing.assert_array_equal(position, START)
        assert heading == 0.0
    walked = fidget + np.array([1.0, 1.0])
    np.testing.assert_allclose(steps[2][0], START + _turned(walked, -45.0), atol=1e-6)
    np.testing.assert_allclose(
        steps[3][0], START + _turned(walked + np.array([1.0, 0.0]), -45.0), atol=1e-6
    )
    assert steps[3][1] == pytest.approx(math.radians(-45.0), abs=1e-6)


def test_by_default_the_first_window_at_walking_speed_sets_the_heading():
    # The first walking window (toward +y) is turned onto +x at once: the fidget before it
    # turned with it, and every window after heads +x.
    steps = _fidget_then_walk(_aligning())
    assert steps[0][1] == 0.0
    for _, heading in steps[1:]:
        assert heading == pytest.approx(0.0, abs=1e-6)  # float32 network
    fidget = 0.3 * 0.98 * np.array([math.cos(math.pi / 3), math.sin(math.pi / 3)])
    walked = fidget + np.array([0.0, 1.0])
    np.testing.assert_allclose(steps[1][0], START + _turned(walked, -90.0), atol=1e-6)


def test_without_a_walking_speed_the_first_confident_window_sets_the_heading():
    # align_speed_mps 0: the fidget, the first window at min_speed_mps, is taken as the
    # way walked (the old rule): the walk that follows comes out 30° off (90° − 60°).
    steps = _fidget_then_walk(_aligning(align_speed_mps=0.0))
    assert steps[3][1] == pytest.approx(math.radians(30.0), abs=1e-6)  # float32 network


def test_alignment_settings_must_not_be_negative():
    with pytest.raises(ValueError, match="align_speed_mps"):
        LearnedIO(align_distance_m=-1.0)


def _slow_then_walk(est: LearnedIO, slow_s: float, slow, walk_s: float = 0.0):
    """``slow_s`` of a phone read as moving at ``slow`` (m/s, x and y), then ``walk_s`` of
    walking at 1 m/s toward +y, in 1 s windows; the last estimate returned."""
    n = round(50 * (slow_s + walk_s))
    t = np.arange(n) / 50.0
    push = np.tile([0.0, 1.0, 9.81], (n, 1))
    push[: round(50 * slow_s), :2] = slow
    for k in range(0, n, 50):
        s = slice(k, k + 50)
        position = est.act(_obs(t[s], push[s], np.zeros((50, 3)), _yaw(np.zeros(50))))
    return position, t


def test_a_walk_that_never_reaches_walking_speed_is_aligned_on_its_own_way():
    # 0.3 m/s toward +y for 32 s: under walking speed throughout, so after 30 s of it
    # the way it went (+y) sets the frame, turned onto the start heading (+x).
    est = _aligning()
    position, t = _slow_then_walk(est, 32.0, (0.0, 0.3))
    assert not est._align_pending
    assert est.heading == pytest.approx(0.0, abs=1e-6)
    np.testing.assert_allclose(position, START + np.array([0.3 * t[-1], 0.0]), atol=1e-5)


def test_a_long_fidget_does_not_set_the_frame_before_the_walk():
    # 12 s of a standing phone read as 0.3 m/s toward 60°, then walking toward +y: the
    # walk, not the fidget, sets the frame (the fidget's drift is turned with it).
    est = _aligning()
    fidget = 0.3 * np.array([math.cos(math.pi / 3), math.sin(math.pi / 3)])
    _slow_then_walk(est, 12.0, fidget, walk_s=3.0)
    assert est.heading == pytest.approx(0.0, abs=1e-6)


def test_while_the_frame_is_pending_every_answer_is_the_start():
    # A window without a rotation vector while still slow: the start, not the drift.
    est = _aligning()
    _slow_then_walk(est, 2.0, (0.0, 0.3))
    t = 2.0 + np.arange(50) / 50.0
    obs = _obs(t, np.tile([0.0, 0.3, 9.81], (50, 1)), np.zeros((50, 3)), _yaw(np.zeros(50)))
    obs["present"][PRESENT_ORDER.index("rotation")] = 0
    obs["rotation"] = np.full((50, 4), np.nan)
    np.testing.assert_array_equal(est.act(obs), START)


def test_a_nan_prediction_does_not_set_the_frame():
    est = _aligning()
    assert np.array_equal(est._align(np.array([np.nan, 1.0]), 1.0), [np.nan, 1.0], equal_nan=True)
    assert est._align_pending and not est._slow_s
