"""Exports read back by readers nobody here wrote: the MCAP file with PyPI's `mcap` and
`mcap-ros2-support` (which decodes the CDR message with its ros2msg schema), every point compared
with the joint trajectory file; wrong inputs refused with nothing written."""

import json
import os
import subprocess
from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

import extreme_line_motion as elm

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"


def nanoseconds(time):
    return time["sec"] * 1_000_000_000 + time["nanosec"]


@pytest.fixture(scope="module")
def ur5e_line(tmp_path_factory):
    """The UR5e's demo line planned by the CLI (`emg plan --robot ur5e`)."""
    directory = tmp_path_factory.mktemp("export")
    subprocess.run(
        [os.environ.get("EMG_CLI", "emg"), "plan", "--robot", "ur5e", "--out", "demo"],
        cwd=directory,
        check=True,
        capture_output=True,
    )
    return directory / "demo.joint_trajectory.json"


def assert_mcap_holds_the_points_of(motion, out, report):
    """The MCAP `out` holds one JointTrajectory message whose points are samples of `motion` (a
    joint trajectory file or a job's program) at their times, the first and the last kept."""
    trajectory = json.loads(motion.read_text())
    by_time = {nanoseconds(p["time_from_start"]): p for p in trajectory["points"]}
    with open(out, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        decoded = list(reader.iter_decoded_messages())
    assert len(decoded) == 1
    schema, channel, _, message = decoded[0]
    assert schema.name == "trajectory_msgs/msg/JointTrajectory"
    assert schema.encoding == "ros2msg" and channel.message_encoding == "cdr"
    assert channel.topic == "/scaled_joint_trajectory_controller/joint_trajectory"
    assert message.header.frame_id == "base"
    assert list(message.joint_names) == trajectory["joint_names"]
    assert len(message.points) == report.points_after
    times = [nanoseconds({"sec": p.time_from_start.sec, "nanosec": p.time_from_start.nanosec})
             for p in message.points]
    assert times[0] == 0
    assert times[-1] == nanoseconds(trajectory["points"][-1]["time_from_start"])
    assert times == sorted(times)
    for point, time in zip(message.points, times):
        sample = by_time[time]
        assert list(point.positions) == sample["positions"]
        assert list(point.velocities) == sample["velocities"]
        assert list(point.accelerations) == sample["accelerations"]
        assert list(point.effort) == []


def test_ros2_mcap_holds_every_point_of_the_file(ur5e_line, tmp_path):
    out = tmp_path / "demo.mcap"
    report = elm.export(ur5e_line, "ros2-mcap", out)
    assert report.files == [out]
    assert report.max_joint_deviation_rad <= report.tolerance_rad == 1e-5
    assert report.points_after < report.points_before / 10
    assert_mcap_holds_the_points_of(ur5e_line, out, report)


def test_a_job_of_several_strokes_exports_as_one_trajectory(tmp_path):
    """A lucide icon planned by `emg job` on the UR5e: its whole program in one message."""
    icon = Path(__file__).resolve().parents[2] / "io" / "tests" / "data" / "icons" / "pencil.svg"
    subprocess.run(
        [os.environ.get("EMG_CLI", "emg"), "job", icon, "--robot", "ur5e", "--out", "pencil.job.json"],
        cwd=tmp_path,
        check=True,
        capture_output=True,
    )
    job = tmp_path / "pencil.job.json"
    strokes = [s for s in json.loads(job.read_text())["segments"] if s["kind"] == "stroke"]
    assert len(strokes) >= 2
    out = tmp_path / "pencil.mcap"
    report = elm.export(job, "ros2-mcap", out)
    assert report.max_joint_deviation_rad <= report.tolerance_rad
    assert_mcap_holds_the_points_of(job, out, report)


def test_urscript_and_wrong_inputs(ur5e_line, tmp_path):
    report = elm.export(ur5e_line, "urscript", tmp_path / "demo.script")
    assert report.servoj_targets > 0
    lines = (tmp_path / "demo.script").read_text().splitlines()
    servoj = [line for line in lines if line.strip().startswith("servoj(")]
    assert len(servoj) == report.servoj_targets + 1  # the stream, then the hold at the end
    out = tmp_path / "none"
    bad = EXAMPLES / "bad.joint_trajectory.json"
    with pytest.raises(elm.InputError, match="Universal Robots controllers only"):
        elm.export(bad, "urscript", out, robot="fr3")
    with pytest.raises(elm.InputError, match="unknown export format 'ros3'"):
        elm.export(ur5e_line, "ros3", out)
    with pytest.raises(elm.InputError, match="is not a joint trajectory"):
        elm.export(EXAMPLES / "plan.json", "ros2-mcap", out)
    with pytest.raises(elm.InputError, match="which is the joint trajectory file"):
        elm.export(ur5e_line, "ros2-mcap", ur5e_line)
    assert not out.exists()
