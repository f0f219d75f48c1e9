"""g1_control/fanout.py: the same results in the same order in this process, in --jobs processes and
on a local Ray cluster (num_cpus=2): execution-suite trials compared to the last simulated tick,
library rollouts compared frame by frame; and the errors a person gets for a bad --jobs/--ray, a
missing Ray, or a cluster that does not answer."""

from __future__ import annotations

import os
import socket
import sys
import time

import numpy as np
import pytest

from g1_control.cli.main import main as g1
from g1_control.errors import FanOutError
from g1_control.fanout import fan_out, parse_address, start_local_ray
from g1_control.library.builder import rollout_job
from g1_control.tools import bench_execution as bench


def _square(x: int) -> int:
    return x * x


def test_results_come_back_in_the_order_of_the_tasks_in_this_process_and_in_processes():
    tasks = list(range(7))
    assert list(fan_out(_square, tasks)) == [x * x for x in tasks]
    assert list(fan_out(_square, tasks, jobs=3)) == [x * x for x in tasks]
    # in processes: the workers are other processes (the pids differ from this one)
    pids = set(fan_out(_pid, range(4), jobs=2))
    assert os.getpid() not in pids


def _pid(_: int) -> int:
    time.sleep(0.05)
    return os.getpid()


def test_bad_jobs_and_addresses_are_refused_before_anything_runs():
    with pytest.raises(FanOutError, match=r"^--jobs 0: expected 1 or more worker processes$"):
        fan_out(_square, [1], jobs=0)
    with pytest.raises(FanOutError, match=r"--ray 'nowhere': expected local \(a Ray on every core"):
        fan_out(_square, [1], ray="nowhere")
    with pytest.raises(FanOutError, match=r"^--ray local:0: expected local:CPUS with CPUS a whole number >= 1$"):
        parse_address("local:0")
    assert parse_address("local") == (None, None)
    assert parse_address("local:3") == (None, 3)
    assert parse_address("10.0.0.5:6379") == ("10.0.0.5:6379", None)


def test_without_ray_installed_the_error_says_how_to_install_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` raises ImportError
    with pytest.raises(FanOutError, match=r"^--ray needs Ray, which is not installed here: pip install "
                                          r"'g1-control\[ray\]' \(or: pip install ray\)$"):
        fan_out(_square, [1], ray="local")


def _closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_an_address_where_no_cluster_answers_is_refused_at_once():
    port = _closed_port()
    t0 = time.perf_counter()
    with pytest.raises(FanOutError, match=rf"^--ray 127.0.0.1:{port}: no Ray cluster answers there \(Connection "
                                          r"refused within 5 s\); start one with `ray start --head`"):
        fan_out(_square, [1], ray=f"127.0.0.1:{port}")
    assert time.perf_counter() - t0 < 5.0  # not Ray's own minutes of retries


def test_the_command_line_says_which_benches_fan_out_and_names_an_unreachable_cluster(capsys):
    assert g1(["bench", "loop", "--jobs", "2"]) == 1
    assert "g1 bench: error: --jobs/--ray: loop runs in this process; they apply to bottle, execution, objects, program" in \
        capsys.readouterr().err
    port = _closed_port()
    assert g1(["bench", "execution", "--only", "walk.default.vx0.5", "--ray", f"127.0.0.1:{port}"]) == 1
    assert f"g1 bench: error: --ray 127.0.0.1:{port}: no Ray cluster answers there" in capsys.readouterr().err


def test_a_local_ray_started_for_the_fan_out_is_stopped_after_it():
    import ray

    assert not ray.is_initialized()
    # a function of the standard library: Ray's workers import it by name, as they import g1_control's
    assert list(fan_out(os.path.basename, ["a/b", "c/d", "e/f"], ray="local:2")) == ["b", "d", "f"]
    assert not ray.is_initialized()


@pytest.fixture(scope="module")
def local_ray():
    """One local Ray of 2 CPUs for the comparisons below, started as `--ray local:2` starts it (fan_out
    uses a Ray the caller started and leaves it running)."""
    import ray

    start_local_ray(cpus=2)
    yield ray
    ray.shutdown()


def test_execution_trials_on_ray_equal_the_jobs_1_run_to_the_last_tick(local_ray):
    rows = {b.name: b for b in bench.behaviours()}
    chosen = [rows["push.stand"], rows["walk.default.vx0.5"]]
    tasks = [t for t in bench.trial_tasks(chosen, seed=3, video=True) if t.behaviour != "push.stand" or t.index < 2]
    tasks = [bench.TrialTask(t.behaviour, t.seed, t.index, keep_log=True) for t in tasks]
    assert [(t.behaviour, t.index) for t in tasks] == [("push.stand", 0), ("push.stand", 1), ("walk.default.vx0.5", 0)]
    here = list(fan_out(bench.run_task, tasks, jobs=1))
    on_ray = list(fan_out(bench.run_task, tasks, ray="local"))
    assert local_ray.is_initialized()  # the caller's Ray is left running
    assert [o.ground_truth() for o in on_ray] == [o.ground_truth() for o in here]
    assert [o.name for o in here] == ["push stand front 0", "push stand front 1", "walk default vx0.5"]
    assert here[0].end_base_pos_m != here[1].end_base_pos_m  # different seeded pushes: different outcomes
    assert here[2].verdict.values["velocity_error_pct"] < 15.0
    for a, b in zip(here, on_ray, strict=True):
        assert a.log is not None and b.log is not None and a.log.keys() == b.log.keys()
        for key in a.log:
            np.testing.assert_array_equal(a.log[key], b.log[key], err_msg=f"{a.name}: {key}")
        assert b.tracker_s is not None and b.tracker_s.size == len(b.log["t_s"])  # timings came back too


def test_library_rollouts_on_ray_equal_the_jobs_1_rollouts(local_ray):
    tasks = [("default", 100, 2.0, 30.0), ("carry", 101, 2.0, 30.0)]
    here = list(fan_out(rollout_job, tasks, jobs=1))
    on_ray = list(fan_out(rollout_job, tasks, ray="local"))
    for (clip, info), (ray_clip, ray_info) in zip(here, on_ray, strict=True):
        assert clip is not None and ray_clip is not None
        assert (clip.style, clip.num_frames, info) == (ray_clip.style, ray_clip.num_frames, ray_info)
        np.testing.assert_array_equal(clip.joint_pos_rad, ray_clip.joint_pos_rad)
        np.testing.assert_array_equal(clip.root_pos_w_m, ray_clip.root_pos_w_m)
    assert not np.array_equal(here[0][0].joint_pos_rad, here[1][0].joint_pos_rad)
