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


def assert_mcap_holds_the_points_of(trajectory, out, report):
    """The MCAP `out` holds one JointTrajectory message whose points are samples of `trajectory`
    (a joint trajectory file's JSON: `joint_names` and `points`) at their times, the first and the
    last kept."""
    by_time = {nanoseconds(p["time_from_start"]): p for p in trajectory["points"]}
    with open(out, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        decoded = list(reader.iter_decoded_messages(
            topics=["/scaled_joint_trajectory_controller/joint_trajectory"]))
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


def samples_of(plan, joint_names):
    """A job's samples (`JobPlan`) in a joint trajectory file's layout."""
    def at(seconds):
        nanoseconds = round(seconds * 1e9)
        return {"sec": nanoseconds // 1_000_000_000, "nanosec": nanoseconds % 1_000_000_000}

    return {
        "joint_names": joint_names,
        "points": [
            {"positions": list(q), "velocities": list(qd), "accelerations": list(qdd),
             "time_from_start": at(t)}
            for t, q, qd, qdd in zip(plan.time_s, plan.q, plan.qd, plan.qdd)
        ],
    }


def test_ros2_mcap_holds_every_point_of_the_file(ur5e_line, tmp_path):
    out = tmp_path / "demo.mcap"
    report = elm.export(ur5e_line, "ros2-mcap", out)
    assert report.files == [out]
    assert report.max_joint_deviation_rad <= report.tolerance_rad == 1e-5
    assert report.points_after < report.points_before / 10
    assert_mcap_holds_the_points_of(json.loads(ur5e_line.read_text()), out, report)


def test_a_job_of_several_strokes_exports_as_one_trajectory(tmp_path):
    """A lucide icon planned as `emg job` plans it on the UR5e: its whole program in one
    message, every sample the program's."""
    icon = Path(__file__).resolve().parents[2] / "io" / "tests" / "data" / "icons" / "pencil.svg"
    plan = elm.Planner("ur5e").plan_job(icon)
    job = tmp_path / "pencil.job.json"
    plan.write(job)
    program = json.loads(job.read_text())
    strokes = [s for s in program["segments"] if s["kind"] == "stroke"]
    assert len(strokes) >= 2
    out = tmp_path / "pencil.mcap"
    report = elm.export(job, "ros2-mcap", out)
    assert report.max_joint_deviation_rad <= report.tolerance_rad
    assert_mcap_holds_the_points_of(samples_of(plan, program["joint_names"]), out, report)
    # The tool switched on where each stroke part starts and off where it ends, beside the
    # trajectory, at those times from its start.
    with open(out, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        switches = [(channel.topic, schema.name, record.log_time, message.data)
                    for schema, channel, record, message
                    in reader.iter_decoded_messages(topics=["/emg/tool_output"])]
        metadata = {m.name: m.metadata for m in reader.iter_metadata()}
    expected = [(round(s[key] * 1e9), on) for s in strokes
                for key, on in (("start_s", True), ("end_s", False))]
    assert [(t, on) for _, _, t, on in switches] == expected
    assert {(topic, name) for topic, name, _, _ in switches} == {
        ("/emg/tool_output", "std_msgs/msg/Bool")}
    assert metadata["emg_export"]["tool_output"].startswith("standard digital output 0")


def test_a_job_exports_as_one_native_ur_program(tmp_path):
    """A job's program on the UR5e as one native program: the tool switched on and off once
    per stroke part, each stroke a movep run."""
    icon = Path(__file__).resolve().parents[2] / "io" / "tests" / "data" / "icons" / "pencil.svg"
    job = tmp_path / "pencil.job.json"
    elm.Planner("ur5e").plan_job(icon).write(job)
    parts = sum(1 for s in json.loads(job.read_text())["segments"] if s["kind"] == "stroke")
    out = tmp_path / "pencil.script"
    report = elm.export(job, "urscript", out)
    assert report.files == [out] and report.servoj_targets == 0
    assert "native: one program" in report.summary
    lines = [line.strip() for line in out.read_text().splitlines()]
    assert lines.count("set_standard_digital_out(0, True)") == parts
    assert sum(line.startswith("movep(") for line in lines) >= parts
    assert not any(line.startswith("servoj(") for line in lines)
    servoj = elm.export(job, "urscript", tmp_path / "stream.script", urscript="servoj",
                        max_servoj_lines=100_000)
    assert servoj.servoj_targets > 0
    with pytest.raises(elm.InputError, match="urscript is 'fast'"):
        elm.export(job, "urscript", tmp_path / "x.script", urscript="fast")


def test_a_job_exports_as_one_rapid_module(tmp_path):
    """A job's program on the IRB 120 as one RAPID module: the tool switched on and off once per
    stroke part, each stroke a MoveL run; a joint trajectory is refused."""
    icon = Path(__file__).resolve().parents[2] / "io" / "tests" / "data" / "icons" / "pencil.svg"
    job = tmp_path / "pencil.job.json"
    elm.Planner("irb120").plan_job(icon).write(job)
    parts = sum(1 for s in json.loads(job.read_text())["segments"] if s["kind"] == "stroke")
    out = tmp_path / "pencil.job.mod"
    report = elm.export(job, "rapid", out)
    assert report.files == [out] and "RAPID for an ABB controller" in report.summary
    lines = [line.strip() for line in out.read_text().splitlines()]
    assert lines[0] == "MODULE EmgJob" and lines[-1] == "ENDMODULE"
    assert lines.count("SetDO doEmgTool0, 1;") == parts
    assert sum(line.startswith("MoveL ") for line in lines) >= parts


def test_a_job_exports_as_one_krl_program(tmp_path):
    """A job's program on the KR 16 as a KRL program: the .src with the tool switched on and off
    once per stroke part, each stroke a LIN run, and its points in the .dat beside it."""
    icon = Path(__file__).resolve().parents[2] / "io" / "tests" / "data" / "icons" / "pencil.svg"
    job = tmp_path / "pencil.job.json"
    elm.Planner("kr16").plan_job(icon).write(job)
    parts = sum(1 for s in json.loads(job.read_text())["segments"] if s["kind"] == "stroke")
    out = tmp_path / "pencil.src"
    report = elm.export(job, "krl", out)
    assert report.files == [out, tmp_path / "pencil.dat"]
    assert "KRL for a KUKA controller" in report.summary
    lines = [line.strip() for line in out.read_text().splitlines()]
    assert lines[2] == "DEF pencil( )" and lines[-1] == "END"
    assert lines.count("$OUT[1]=TRUE") == parts
    assert sum(line.startswith("LIN ") for line in lines) >= parts
    assert (tmp_path / "pencil.dat").read_text().splitlines()[2] == "DEFDAT pencil"
    with pytest.raises(elm.InputError, match="not a KRL name"):
        elm.export(job, "krl", tmp_path / "my-pencil.src")


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
