"""Animations: the slider-crank with each clearance joint, a chain and a scene file render to GIFs with
the expected frame count; bad options fail before rendering with the field, the value and the rule;
``daeclear animate`` works on a saved result."""

import math

import numpy as np
import pytest
from PIL import Image

import daeclear as dc
from daeclear.plot.animate import MAX_FRAMES, frame_count, frame_times
from daeclear.cli import main
from daeclear.core.errors import MissingDependencyError, OutputError
from daeclear.model.mechanisms import chain, slider_crank
from daeclear.model.scenefile import read_scene_file
from scene_texts import PENDULUM

SMALL = (320, 200)

PENDULUM_TOML = PENDULUM


@pytest.fixture(scope="module")
def revolute():
    return dc.simulate(slider_crank("revolute"), 0.004)


@pytest.fixture(scope="module")
def translational():
    return dc.simulate(slider_crank("translational"), 0.004)


def _frames(path):
    with Image.open(path) as im:
        return im.n_frames, im.info.get("duration")


def _red_frames(path):
    """Frames with strongly red pixels (contact highlighted)."""
    count = 0
    with Image.open(path) as im:
        for k in range(im.n_frames):
            im.seek(k)
            rgb = np.asarray(im.convert("RGB")).astype(int)
            if np.any((rgb[..., 0] > 180) & (rgb[..., 1] < 90) & (rgb[..., 2] < 90)):
                count += 1
    return count


def test_frame_rule():
    assert frame_count(0.002, 300.0, 10.0) == 6
    assert frame_count(0.004, 1000.0, 25.0) == 100
    assert frame_count(1e-6, 1.0, 1.0) == 2  # never fewer than two frames
    times = frame_times(0.001, 0.003, 6)
    assert times[0] == 0.001 and times[-1] == 0.003 and np.allclose(np.diff(times), 0.0004)


def test_revolute_slider_crank(revolute, tmp_path):
    path = dc.animate(revolute, tmp_path / "revolute.gif", fps=10, window=(0.001, 0.003), slow_motion=300, size=SMALL)
    assert path == tmp_path / "revolute.gif"
    assert path.stat().st_size > 5_000
    assert _frames(path) == (frame_count(0.002, 300, 10), 100)  # 6 frames of 100 ms
    with Image.open(path) as im:
        assert im.size == SMALL
    assert list(tmp_path.iterdir()) == [path]  # no temporary file left


def test_contact_is_highlighted(revolute, tmp_path):
    # the journal hits the bearing several times in the first 4 ms (cursor plot shaded, ring and dot red)
    assert revolute["clearance.in_contact"].max() > 0
    path = dc.animate(revolute, tmp_path / "hits.gif", fps=10, slow_motion=200, size=SMALL)
    n, _ = _frames(path)
    assert n == 8
    assert 0 < _red_frames(path) <= n


def test_translational_slider_crank(translational, tmp_path, capsys):
    path = dc.animate(translational, tmp_path / "translational.gif", fps=20, slow_motion=100, size=SMALL,
                                 channel="slider.vx", magnify=20, progress=True)
    assert path.stat().st_size > 5_000
    assert _frames(path) == (8, 50)  # round(0.004 s x 100 x 20)
    assert "animating translational.gif: 8/8 frames  100.0 %" in capsys.readouterr().err  # daeclear/core/progress.py


def test_chain_and_scene_file(tmp_path):
    links = dc.simulate(chain(2), 0.02)
    path = dc.animate(links, tmp_path / "chain.gif", fps=10, slow_motion=20, size=SMALL)
    assert _frames(path)[0] == 4
    scene_file = tmp_path / "pendulum.toml"
    scene_file.write_text(PENDULUM_TOML)
    pendulum = dc.simulate(read_scene_file(scene_file).scene, 0.2)
    path = dc.animate(pendulum, tmp_path / "pendulum.gif", fps=10, slow_motion=3, size=SMALL)  # no clearance joint
    assert _frames(path)[0] == 6
    assert path.stat().st_size > 2_000


def test_default_slow_motion_plays_in_five_seconds(revolute, tmp_path):
    path = dc.animate(revolute, tmp_path / "default.gif", fps=2, window=(0.0, 0.002), size=SMALL)
    assert _frames(path)[0] == 10  # 5 s at 2 frames per second


@pytest.mark.parametrize(
    "options, text",
    [
        ({"fps": 0}, "fps=0, must be a finite number > 0 and <= 100"),
        ({"fps": -5.0}, "fps=-5.0"),
        ({"fps": math.nan}, "fps=nan"),
        ({"fps": 500}, "fps=500"),
        ({"fps": "25"}, "fps='25'"),
        ({"window": (0.003, 0.001)}, "window=(0.003, 0.001) s, must be (t0, t1)"),
        ({"window": (0.001, 0.001)}, "t0 < t1"),
        ({"window": (-1.0, 0.002)}, "window=(-1.0, 0.002) s"),
        ({"window": (0.0, 1.0)}, "t1 <= 0.004"),
        ({"window": 0.002}, "window=0.002"),
        ({"window": (0.0, "end")}, "window=(0.0, 'end')"),
        ({"slow_motion": 0}, "slow_motion=0, must be a finite number > 0"),
        ({"slow_motion": -10.0}, "slow_motion=-10.0"),
        ({"size": (10, 10)}, "size=(10, 10), must be (width, height) in pixels"),
        ({"size": (320.5, 200)}, "size=(320.5, 200)"),
        ({"size": 320}, "size=320"),
        ({"channel": "slider.vxx"}, "channel='slider.vxx', must be a channel of the result (close: slider.vx"),
        ({"channel": 3}, "channel=3"),
        ({"magnify": 0}, "magnify=0, must be a finite number > 0"),
        ({"progress": "yes"}, "progress='yes', must be True or False"),
        ({"slow_motion": 1e6}, f"must be at most {MAX_FRAMES}"),
    ],
)
def test_bad_options_raise(revolute, tmp_path, options, text):
    with pytest.raises(dc.SceneError) as info:
        dc.animate(revolute, tmp_path / "bad.gif", **{"size": SMALL, **options})
    assert text in str(info.value)
    assert str(info.value).startswith("animate: ")
    assert list(tmp_path.iterdir()) == []  # nothing rendered


def test_bad_path_fails_before_rendering(revolute, tmp_path):
    with pytest.raises(dc.SceneError, match=r"path='.*run\.avi', must be an animation file ending in \.gif"):
        dc.animate(revolute, tmp_path / "run.avi", size=SMALL)
    with pytest.raises(OutputError, match="does not exist"):
        dc.animate(revolute, tmp_path / "missing" / "run.gif", size=SMALL)
    with pytest.raises(OutputError, match="is a directory"):
        dc.animate(revolute, tmp_path, size=SMALL)


def test_mp4_without_ffmpeg_names_the_program(revolute, tmp_path, monkeypatch):
    import matplotlib

    monkeypatch.setitem(matplotlib.rcParams, "animation.ffmpeg_path", "no-such-ffmpeg-program")
    with pytest.raises(MissingDependencyError, match="needs the program ffmpeg.*no-such-ffmpeg-program.*\\.gif"):
        dc.animate(revolute, tmp_path / "run.mp4", size=SMALL)
    assert list(tmp_path.iterdir()) == []


def test_result_without_scene_description(revolute, tmp_path):
    bare = dc.Result(**{**revolute.to_dict(), "parameters": {}})
    with pytest.raises(dc.SceneError, match="no scene description"):
        dc.animate(bare, tmp_path / "bare.gif", size=SMALL)


def test_cli_animates_a_saved_result(translational, tmp_path, capsys):
    h5 = translational.save(tmp_path / "run.h5")
    out = tmp_path / "run_anim.gif"
    code = main(["animate", str(h5), "--out", str(out), "--fps", "10", "--window", "0.001", "0.003",
                 "--slow-motion", "300", "--size", "320", "200", "--channel", "slider.vx", "--quiet"])
    assert code == 0
    assert _frames(out) == (6, 100)
    assert f"wrote {out}" in capsys.readouterr().out
    # default output: the result's name with .gif
    assert main(["animate", str(h5), "--fps", "5", "--slow-motion", "100", "--size", "320", "200"]) == 0
    assert _frames(tmp_path / "run.gif")[0] == 2
    assert "animating run.gif: 2/2 frames  100.0 %" in capsys.readouterr().err  # daeclear/core/progress.py


@pytest.mark.parametrize(
    "args, text",
    [
        (["--fps", "0"], "daeclear animate: --fps=0.0, must be a finite number > 0"),
        (["--window", "0.003", "0.001"], "--window=(0.003, 0.001) s, must be (t0, t1)"),
        (["--slow-motion", "-1"], "--slow-motion=-1.0"),
        (["--size", "10", "10"], "--size=(10, 10)"),
        (["--channel", "slider.vxx"], "--channel='slider.vxx'"),
        (["--out", "run.avi"], "--out='run.avi', must be an animation file"),
        (["--out", "missing/run.gif"], "does not exist"),
    ],
)
def test_cli_bad_input_exits_2(translational, tmp_path, capsys, monkeypatch, args, text):
    h5 = translational.save(tmp_path / "run.h5")
    monkeypatch.chdir(tmp_path)
    assert main(["animate", str(h5), "--quiet", *args]) == 2
    err = capsys.readouterr().err
    assert text in err
    assert err.count("\n") == 1  # one line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.h5"]


def test_cli_missing_result_file(tmp_path, capsys):
    assert main(["animate", str(tmp_path / "nope.h5")]) == 2
    assert "no result file" in capsys.readouterr().err


@pytest.mark.filterwarnings("ignore::daeclear.DaeclearWarning")  # the run's drift note, not the animation's
def test_fig4_15_example_script(tmp_path):
    import importlib.util
    from pathlib import Path

    script = Path(__file__).resolve().parent.parent / "examples" / "animate_fig4_15.py"
    spec = importlib.util.spec_from_file_location("animate_fig4_15", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    out = tmp_path / "fig.gif"
    assert module.main(["--out", str(out), "--revolutions", "1", "--span", "2", "--slow-motion", "100",
                        "--fps", "10", "--size", "200", "160"]) == 0
    assert _frames(out) == (2, 100)


def test_contact_state_of_a_frame():
    """In contact at the frame's time, an impact since the previous frame (over by now), or free."""
    from daeclear.plot.mechanism_frame import CONTACT, FREE, IMPACT
    from daeclear.plot.mechanism_frame import Sampler as _Sampler, contact_state as _contact_state

    t = np.arange(5.0)
    result = dc.Result(t=t, y=np.zeros((5, 0)), yp=np.zeros((5, 0)), state_names=[], units={},
                       channels={"j.in_contact": [0, 0, 1, 0, 0], "j.penetration": [-1e-4, -1e-4, 2e-6, -1e-4, -1e-4]})
    times = np.array([0.0, 1.5, 2.0, 4.0])
    state, depth = _contact_state(_Sampler(result, times, 0.0, 4.0), "j")
    assert list(state) == [FREE, FREE, CONTACT, FREE]
    assert depth[2] == pytest.approx(2e-6)
    times = np.array([0.0, 1.5, 3.5])  # the contact at t = 2 falls between two frames
    state, depth = _contact_state(_Sampler(result, times, 0.0, 4.0), "j")
    assert list(state) == [FREE, FREE, IMPACT]
    assert depth[2] == pytest.approx(2e-6)


def test_a_failed_animation_leaves_the_old_file_and_no_temporary(revolute, tmp_path, monkeypatch):
    """The animation writes through results.outputs.atomic_file (a temporary name that keeps the
    suffix the writer reads): an error while rendering leaves an existing file untouched and no
    temporary file behind; a finished one replaces it."""
    import matplotlib.animation

    target = tmp_path / "run.gif"
    target.write_bytes(b"old")
    seen = []

    def broken_grab(self, **kwargs):
        seen.append(self.outfile)
        raise OSError("disk full")

    monkeypatch.setattr(matplotlib.animation.PillowWriter, "grab_frame", broken_grab)
    with pytest.raises(OSError, match="disk full"):
        dc.animate(revolute, target, fps=10, window=(0.001, 0.002), slow_motion=100, size=SMALL)
    assert seen and str(seen[0]).endswith(".gif") and seen[0] != str(target)
    assert target.read_bytes() == b"old" and list(tmp_path.iterdir()) == [target]
    monkeypatch.undo()
    dc.animate(revolute, target, fps=10, window=(0.001, 0.002), slow_motion=100, size=SMALL)
    assert target.read_bytes()[:3] == b"GIF" and list(tmp_path.iterdir()) == [target]
