//! The RAPID modules `emg job --export rapid` writes for the ABB IRB 120, read back by the
//! independent reader (`emg-rapid-check`: its own parser, the arm's closed form from
//! `rs-opw-kinematics`, ABB's configuration data computed from that geometry, the checker's
//! clearances) and checked against the job's plan; the module of a small job kept word for word;
//! edits of a module refused at their line.

mod common;

use std::path::{Path, PathBuf};

use common::{
    assert_export_refused_before_planning, assert_golden, case, data_dir, emg, job_exported,
    line_of, read, temp_dir, text, triangle, with_line,
};
use emg_rapid_check::{RapidReport, ReadError, read_rapid};
use emg_verify::ReferenceModel;

/// The shipped IRB 120's checker, base `base_link`, tip `pen_tip`.
fn irb120_checker() -> ReferenceModel {
    ReferenceModel::from_urdf_file(
        &data_dir().join("robots/irb120_pen.urdf"),
        "base_link",
        "pen_tip",
    )
    .expect("the IRB 120's checker")
}

/// `drawing` planned on the IRB 120 by `emg job ... --export rapid` (with `extra` arguments)
/// into `dir`: the module, its plan and the module's path.
fn exported(drawing: &Path, dir: &Path, extra: &[&str]) -> (String, emg_job::JobFile, PathBuf) {
    let out = dir.join("drawing.job.json");
    let plan = job_exported(drawing, ("irb120", "rapid"), &out, extra);
    let module = out.with_extension("mod");
    (read(&module), plan, module)
}

/// Checks what every module that reads back must show.
fn assert_reads_back(report: &RapidReport, plan: &emg_job::JobFile) {
    let parts = plan
        .segments
        .iter()
        .filter(|s| matches!(s.kind, emg_job::SegmentKind::Stroke { .. }))
        .count();
    assert_eq!(report.drawn.stroke_parts, parts);
    assert!(report.worst_target_rad <= 1e-6, "{report:?}");
    assert!(report.least_spacing_m >= 1e-4, "{report:?}");
    assert!(report.drawn.worst_deviation_m <= plan.constraints.line_tolerance_m);
    assert!(report.drawn.worst_tool_angle_deg <= plan.constraints.theta_max_deg);
    assert!(report.drawn.covered_m >= report.drawn.drawn_m - 1e-3 * parts as f64);
}

#[test]
fn the_house_module_reads_back_every_target_the_plans_configuration() {
    let dir = temp_dir("rapid-house");
    let (module, plan, path) = exported(&case("pen-drag-house.svg"), dir.path(), &[]);
    let report = read_rapid(&module, &plan, &irb120_checker()).expect("the module reads back");
    eprintln!("{report:#?}");
    assert_reads_back(&report, &plan);
    // `emg check` reads it beside its plan.
    let run = emg(&["check", path.to_str().expect("utf-8 path")]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    assert!(text(&run.stdout).contains("RAPID read back"));
}

/// A small job whose module is kept word for word in `tests/data/irb120-triangle.mod`: any
/// change of the writer shows there. `EMG_WRITE_GOLDEN=1` writes it again.
#[test]
fn a_small_job_writes_the_module_kept_word_for_word() {
    let dir = temp_dir("rapid-golden");
    let (module, plan, _) = exported(&triangle(dir.path()), dir.path(), &["--width", "0.05"]);
    // The header names the robot by its digest, no directory of this machine.
    assert!(!module.contains(dir.path().to_str().expect("utf-8 path")));
    assert_golden(&module, "irb120-triangle.mod");
    let report = read_rapid(&module, &plan, &irb120_checker()).expect("the module reads back");
    assert_reads_back(&report, &plan);
    assert_eq!(report.drawn.stroke_parts, 1);
}

#[test]
fn rapid_for_an_arm_of_another_vendor_is_refused_before_anything_is_planned() {
    assert_export_refused_before_planning("rapid", &["kr16", "ur5e", "fr3"]);
}

#[test]
fn edits_of_a_module_are_refused_at_their_line() {
    let dir = temp_dir("rapid-edits");
    let (module, plan, _) = exported(&case("pen-drag-house.svg"), dir.path(), &[]);
    let checker = irb120_checker();
    let refused = |edited: &str| -> ReadError {
        read_rapid(edited, &plan, &checker).expect_err("an edited module is refused")
    };
    let stroke_target = line_of(&module, |l| l.contains("MoveL") && l.contains("zEmg"));
    // A target moved by a millimetre.
    let moved = with_line(&module, stroke_target, |l| {
        let at = l.find("[[").expect("a robtarget") + 2;
        let end = at + l[at..].find(',').expect("x");
        let x: f64 = l[at..end].parse().expect("x in mm");
        format!("{}{:.6}{}", &l[..at], x + 1.0, &l[end..])
    });
    let error = refused(&moved);
    assert_eq!(error.line, stroke_target, "{error}");
    // A configuration bit flipped: cfx's axis-5 bit.
    let flipped = with_line(&module, stroke_target, |l| {
        let conf = l.find("], [").expect("after the position") + 4;
        let conf = conf + l[conf..].find("], [").expect("after the orientation") + 4;
        let end = conf + l[conf..].find(']').expect("confdata");
        let mut values: Vec<i32> = l[conf..end]
            .split(',')
            .map(|v| v.trim().parse().expect("an integer"))
            .collect();
        values[3] ^= 1;
        let values: Vec<String> = values.iter().map(i32::to_string).collect();
        format!("{}{}{}", &l[..conf], values.join(", "), &l[end..])
    });
    let error = refused(&flipped);
    assert_eq!(error.line, stroke_target, "{error}");
    assert!(error.problem.contains("configuration"), "{error}");
    // A zone that is not defined.
    let undefined = with_line(&module, stroke_target, |l| {
        let at = l.find("zEmg").expect("a declared zone");
        let end = at + l[at..].find(',').expect("the zone's end");
        format!("{}zEmgNone{}", &l[..at], &l[end..])
    });
    let error = refused(&undefined);
    assert_eq!(error.line, stroke_target, "{error}");
    assert!(error.problem.contains("not defined"), "{error}");
    // The tool never switched on for the first stroke part.
    let switch = line_of(&module, |l| l.trim() == "SetDO doEmgTool0, 1;");
    let unswitched = with_line(&module, switch, |_| "    ! SetDO left out".to_string());
    let error = refused(&unswitched);
    assert!(error.problem.contains("switches"), "{error}");
    // The tool on a tenth of a millimetre off the pen's axis.
    let tool = line_of(&module, |l| l.contains("PERS tooldata"));
    let off_axis = with_line(&module, tool, |l| {
        l.replacen("[[0.000000, ", "[[0.100000, ", 1)
    });
    let error = refused(&off_axis);
    assert_eq!(error.line, tool, "{error}");
}
