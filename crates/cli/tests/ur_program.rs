//! The URScript programs `emg job --export urscript` writes for the UR5e, native and servoj,
//! read back by the independent reader (`emg-ur-check`: its own parser, the URScript manual's
//! motion semantics, the UR5e's closed-form inverse kinematics, the checker's kinematics and
//! clearances) and checked against the job's plan; edits of a program refused at their line.

mod common;

use std::path::Path;

use common::{case, data_dir, emg, job_exported, read, temp_dir, text};
use emg_ur_check::{
    Form, NativeReport, Pose, ReadError, Statement, parse_program, read_native, read_servoj,
};
use emg_verify::ReferenceModel;

/// The shipped UR5e's checker, base `base_link`, tip `pen_tip`.
fn ur5e_checker() -> ReferenceModel {
    ReferenceModel::from_urdf_file(
        &data_dir().join("robots/ur5e_pen.urdf"),
        "base_link",
        "pen_tip",
    )
    .expect("the UR5e's checker")
}

/// `drawing` planned on the UR5e by `emg job ... --export urscript` (with `extra` arguments)
/// into `dir`: the program's script and its plan.
fn exported(drawing: &Path, dir: &Path, extra: &[&str]) -> (String, emg_job::JobFile) {
    let out = dir.join("house.json");
    let plan = job_exported(drawing, ("ur5e", "urscript"), &out, extra);
    (read(&out.with_extension("script")), plan)
}

/// Reads `script` against `plan`, printing the report.
fn read_back(script: &str, plan: &emg_job::JobFile) -> Result<NativeReport, ReadError> {
    let started = std::time::Instant::now();
    let report = read_native(script, plan, &ur5e_checker(), true);
    eprintln!(
        "read in {:.1} s: {report:#?}",
        started.elapsed().as_secs_f64()
    );
    report
}

/// Checks what every program that reads back must show.
fn assert_reads_back(report: &NativeReport, plan: &emg_job::JobFile) {
    let parts = plan
        .segments
        .iter()
        .filter(|s| matches!(s.kind, emg_job::SegmentKind::Stroke { .. }))
        .count();
    assert_eq!(report.stroke_parts, parts);
    assert!(report.worst_deviation_m <= plan.constraints.line_tolerance_m);
    assert!(report.worst_tool_angle_deg <= plan.constraints.theta_max_deg);
    assert!(report.covered_m >= report.drawn_m - 1e-3 * parts as f64);
    assert!(report.movep > 0 && report.movej > 0);
}

#[test]
fn the_ur5e_house_program_reads_back_within_the_tolerance_and_cone() {
    let tmp = temp_dir("ur-house");
    let (script, plan) = exported(&case("house.svg"), tmp.path(), &[]);
    let report = read_back(&script, &plan).unwrap_or_else(|e| panic!("{e}"));
    assert_reads_back(&report, &plan);
}

#[test]
fn a_cusp_the_samples_turn_at_is_not_cut_short_by_a_line_or_a_blend() {
    // The anchor's arrowheads turn back at cusps. A line or blend ending short of where the
    // samples turned left the reader's progress before the cusp, and the line back out then
    // lay 0.53 mm (a line) or 0.57 mm (a blend) from the stroke it had reached.
    let tmp = temp_dir("ur-anchor");
    let icon = Path::new(env!("CARGO_MANIFEST_DIR")).join("../io/tests/data/icons/anchor.svg");
    let (script, plan) = exported(&icon, tmp.path(), &["--width", "0.15"]);
    let report = read_back(&script, &plan).unwrap_or_else(|e| panic!("{e}"));
    assert_reads_back(&report, &plan);
}

#[test]
fn a_hundred_stroke_ur5e_program_reads_back() {
    let tmp = temp_dir("ur-hundred");
    let drawing = tmp.path().join("scatter.svg");
    std::fs::write(&drawing, emg_io::scattered_strokes_svg(100)).expect("drawing written");
    let (script, plan) = exported(&drawing, tmp.path(), &[]);
    let report = read_back(&script, &plan).unwrap_or_else(|e| panic!("{e}"));
    assert_reads_back(&report, &plan);
    assert_eq!(report.strokes, 100);
    assert!(report.lines_per_stroke <= 20.0, "{report:?}");
}

#[test]
fn a_target_moved_by_a_millimetre_fails_the_reader() {
    let tmp = temp_dir("ur-moved");
    let (script, plan) = exported(&case("house.svg"), tmp.path(), &[]);
    let program = parse_program(&script, Form::Native).expect("the program parses");
    // The longest run of movep lines: its middle target, moved 1 mm across the stroke (in
    // the plane of the neighbouring targets' direction and the tool axis, perpendicular to
    // both).
    let mut runs: Vec<Vec<(usize, Pose)>> = Vec::new();
    let mut previous_line = 0;
    for (line, statement) in &program.statements {
        if let Statement::MoveP { pose, .. } = statement {
            if runs.last().is_none() || *line != previous_line + 1 {
                runs.push(Vec::new());
            }
            runs.last_mut().expect("a run").push((*line, *pose));
            previous_line = *line;
        }
    }
    let run = runs.iter().max_by_key(|r| r.len()).expect("a movep run");
    assert!(run.len() >= 3, "{run:?}");
    let middle = run.len() / 2;
    let (line, pose) = run[middle];
    let along = (run[middle + 1].1.position - run[middle - 1].1.position).normalize();
    let across = pose.rotation.column(2).cross(&along).normalize();
    let mut moved = pose;
    moved.position += across * 1e-3;
    let values = moved.to_ur();
    let lines: Vec<&str> = script.lines().collect();
    let original = lines[line - 1];
    let rest = original
        .split_once("],")
        .map(|(_, rest)| rest)
        .expect("movep(p[...], a=.., v=.., r=..)");
    let indent = &original[..original.len() - original.trim_start().len()];
    let edited_line = format!(
        "{indent}movep(p[{:?}, {:?}, {:?}, {:?}, {:?}, {:?}],{rest}",
        values[0], values[1], values[2], values[3], values[4], values[5]
    );
    let edited: String = lines
        .iter()
        .enumerate()
        .map(|(i, l)| {
            if i + 1 == line {
                format!("{edited_line}\n")
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    // The unedited program reads back; the edited one is refused at the edited line.
    read_back(&script, &plan).unwrap_or_else(|e| panic!("{e}"));
    let error = read_back(&edited, &plan).expect_err("a moved target");
    assert_eq!(error.line, line, "{error}");
    // `emg check` does the same: the program beside its plan passes, the edited one (its plan
    // named) is refused naming the line.
    let written = tmp.path().join("house.script");
    let passed = emg(&["check", written.to_str().expect("utf-8 path")]);
    assert!(passed.status.success(), "{}", text(&passed.stderr));
    assert!(
        text(&passed.stdout).contains("native:"),
        "{}",
        text(&passed.stdout)
    );
    let moved_file = tmp.path().join("moved.script");
    std::fs::write(&moved_file, &edited).expect("edited program written");
    let plan_file = tmp.path().join("house.json");
    let refused = emg(&[
        "check",
        moved_file.to_str().expect("utf-8 path"),
        "--program",
        plan_file.to_str().expect("utf-8 path"),
    ]);
    assert_eq!(refused.status.code(), Some(1));
    let message = text(&refused.stderr);
    assert!(message.contains(&format!("line {line}:")), "{message}");
}

/// `script` with line `line` (1-based) replaced by `with`.
fn with_line(script: &str, line: usize, with: &str) -> String {
    script
        .lines()
        .enumerate()
        .map(|(i, l)| if i + 1 == line { with } else { l })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn edits_of_the_house_program_are_refused_at_their_line() {
    let tmp = temp_dir("ur-edits");
    let (script, plan) = exported(&case("house.svg"), tmp.path(), &[]);
    let checker = ur5e_checker();
    let lines: Vec<&str> = script.lines().collect();
    let find = |from: usize, prefix: &str| {
        (from..lines.len())
            .find(|&i| lines[i].trim_start().starts_with(prefix))
            .map(|i| i + 1)
            .unwrap_or_else(|| panic!("no '{prefix}' after line {from}"))
    };
    let refused_at = |edited: &str, line: usize, on_level: bool, why: &str| {
        let error = read_native(edited, &plan, &checker, on_level).expect_err("refused");
        assert_eq!(error.line, line, "{error}");
        assert!(error.problem.contains(why), "{error}");
    };
    // A movej target 1 µrad off the plan.
    let movej = find(0, "movej(");
    let bent = lines[movej - 1].replacen("movej([", "movej([0.000001 + ", 1);
    let program = parse_program(&with_line(&script, movej, &bent), Form::Native);
    assert!(program.is_err(), "an expression is no number");
    let Statement::MoveJ { q, .. } = parse_program(&script, Form::Native)
        .expect("parses")
        .statements
        .into_iter()
        .find(|(line, _)| *line == movej)
        .expect("the movej")
        .1
    else {
        panic!("line {movej} is a movej");
    };
    let off: Vec<String> = q
        .iter()
        .enumerate()
        .map(|(i, v)| format!("{:?}", if i == 0 { v + 1e-6 } else { *v }))
        .collect();
    let rest = lines[movej - 1]
        .split_once("],")
        .expect("movej([...], a, v)")
        .1;
    refused_at(
        &with_line(
            &script,
            movej,
            &format!("  movej([{}],{rest}", off.join(", ")),
        ),
        movej,
        true,
        "is no configuration of the plan",
    );
    // A blend radius wider than half of a line next to it.
    let blended = (0..lines.len())
        .find(|&i| lines[i].contains("movep(") && !lines[i].contains("r=0.000000000"))
        .map(|i| i + 1)
        .expect("a blended movep");
    let (head, _) = lines[blended - 1].rsplit_once("r=").expect("r=");
    refused_at(
        &with_line(&script, blended, &format!("{head}r=0.5)")),
        blended,
        true,
        "exceeds half of an adjacent line",
    );
    // The tool switched on before the move that sets it down, the lift above its stroke.
    let on = find(0, "set_standard_digital_out(0, True)");
    let set_down = (0..on)
        .rev()
        .find(|&i| lines[i].trim_start().starts_with("movel("))
        .expect("the set-down")
        + 1;
    let mut moved: Vec<&str> = lines.clone();
    let switch = moved.remove(on - 1);
    moved.insert(set_down - 1, switch);
    refused_at(
        &moved.join("\n"),
        set_down,
        true,
        "the tool switches on 2.0000 mm from the start of stroke part 0",
    );
    // The tool's levels swapped: the program reads back when low switches the tool on, and is
    // refused at its first write when high does.
    let swapped = script
        .replace("(0, True)", "(0, Low)")
        .replace("(0, False)", "(0, True)")
        .replace("(0, Low)", "(0, False)");
    read_native(&swapped, &plan, &checker, false).unwrap_or_else(|e| panic!("{e}"));
    refused_at(
        &swapped,
        find(0, "set_standard_digital_out("),
        true,
        "the tool switches on before the first move",
    );
}

/// The joint stream `emg export` writes of the plan at `plan_path` into `dir` (`--urscript
/// servoj`, the default most lines per program): each program's text, in order.
fn exported_stream(plan_path: &Path, dir: &Path) -> Vec<String> {
    let out = dir.join("stream.script");
    let run = emg(&[
        "export",
        plan_path.to_str().expect("utf-8 path"),
        "--format",
        "urscript",
        "--urscript",
        "servoj",
        "--out",
        out.to_str().expect("utf-8 path"),
    ]);
    assert!(
        run.status.success(),
        "emg export failed:\n{}\n{}",
        text(&run.stdout),
        text(&run.stderr)
    );
    if out.is_file() {
        return vec![read(&out)];
    }
    (1..)
        .map(|n| dir.join(format!("stream-part{n}.script")))
        .take_while(|part| part.is_file())
        .map(|part| read(&part))
        .collect()
}

#[test]
fn the_ur5e_house_exported_both_ways_reads_back() {
    let tmp = temp_dir("ur-both");
    let (script, plan) = exported(&case("house.svg"), tmp.path(), &[]);
    let report = read_back(&script, &plan).unwrap_or_else(|e| panic!("{e}"));
    assert_reads_back(&report, &plan);
    let programs = exported_stream(&tmp.path().join("house.json"), tmp.path());
    let scripts: Vec<&str> = programs.iter().map(String::as_str).collect();
    let stream = read_servoj(&scripts, &plan, &ur5e_checker()).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("{stream:#?}");
    assert_eq!(stream.programs, programs.len());
    assert!(stream.home_checked);
    let duration_ns = (stream.duration_s * 1e9).round() as usize;
    assert_eq!(stream.targets, duration_ns.div_ceil(2_000_000));
    assert!(stream.worst_speed_fraction <= 1.0 + 1e-9);
    // The programs in the wrong order are refused: the second does not start where the arm
    // rests.
    if scripts.len() >= 2 {
        let swapped = [scripts[1], scripts[0]];
        let error = read_servoj(&swapped, &plan, &ur5e_checker()).expect_err("swapped");
        assert_eq!(error.program, Some(1), "{error}");
    }
}
