"""``hippomaze animate``: a trial animated into a GIF (and an MP4 with the 'video' extra), which
frames are shown, and clear errors for a bad file type, maze or agent."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest
from PIL import Image

from hippomaze import animate
from hippomaze.cli import main


def test_a_hippo_trial_becomes_a_gif_with_its_three_panels(tmp_path, capsys):
    out = tmp_path / "trial.gif"
    assert main(["animate", "--maze", "open", "--seed", "0", "--runs", "2", "--frames", "12", "--dpi", "30", "--out", str(out)]) == 0
    assert f"wrote {out}" in capsys.readouterr().out
    gif = Image.open(out)
    assert gif.n_frames >= 12 and gif.size[0] > 2.5 * gif.size[1]  # three square panels side by side
    gif.seek(gif.n_frames - 1)
    last = np.asarray(gif.convert("RGB"), dtype=float)
    third = last[:, 2 * last.shape[1] // 3 :]  # the reward map after the runs: coloured, not only grey
    assert np.any(np.ptp(third, axis=2) > 60)


def test_frames_cover_every_phase_and_the_replay():
    recording = animate.Recording(runs=2)
    phases = [0] * 500 + [1] * 300 + [2] * 20
    recording.steps = [animate.Step(p, (0.0, 0.0), 0.0, np.ones(8, np.float32), np.zeros(4, np.float32), "") for p in phases]
    recording.weights_before = {1: np.zeros(4), 2: np.array([0.0, 0.5, 1.0, 0.0])}
    recording.weights_after = {1: np.array([0.0, 0.5, 1.0, 0.0]), 2: np.array([0.0, 0.5, 1.0, 0.0])}
    plan = animate.frame_plan(recording, frames=100)
    shown = [recording.steps[i].phase for i, kind, _ in plan if kind == "step"]
    assert shown.count(0) == 22 and shown.count(1) == 25 and shown.count(2) == 10
    replay = [(i, reveal) for i, kind, reveal in plan if kind == "replay"]
    assert [i for i, _ in replay] == [799] * animate.REPLAY_FRAMES  # run 1 ended with a replay; run 2 added nothing
    assert replay[-1][1] == 1.0
    starts = {0: 0, 1: 500, 2: 800}
    half = animate._weights_at(recording, 1, 799, starts, "replay", 0.5)
    assert half.tolist() == [0.0, 0.0, 1.0, 0.0]  # the largest new weight first


@pytest.mark.skipif(importlib.util.find_spec("imageio_ffmpeg") is None, reason="an mp4 needs the 'video' extra")
def test_an_mp4_with_the_video_extra(tmp_path):
    out = tmp_path / "trial.mp4"
    animate.animate("open", 1, out, agent="random", runs=1, frames=10, dpi=30)
    assert out.read_bytes()[4:8] == b"ftyp"


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--out", "trial.avi"], "must end in .gif or .mp4"),
        (["--maze", "maze9", "--out", "trial.gif"], "maze 'maze9' is unknown"),
        (["--agent", "no_such_module:Agent", "--out", "trial.gif"], "cannot import module 'no_such_module'"),
        (["--runs", "0", "--out", "trial.gif"], "--runs must be an integer >= 1"),
    ],
)
def test_bad_input_is_a_clear_error(tmp_path, monkeypatch, capsys, args, message):
    monkeypatch.chdir(tmp_path)
    assert main(["animate", *args]) == 2
    assert message in capsys.readouterr().err
    assert not list(tmp_path.iterdir())
