//! The KRL programs `emg job --export krl` writes for the KUKA KR 16-2, read back by the
//! independent reader (`emg-krl-check`: its own parser, the arm's closed form from
//! `rs-opw-kinematics`, KUKA's Status and Turn computed from that geometry, the checker's
//! clearances) and checked against the job's plan; the program of a small job kept word for
//! word; edits of a program refused at their line.

mod common;

use std::path::{Path, PathBuf};

use common::{
    assert_export_refused_before_planning, assert_golden, case, data_dir, emg, job_exported,
    line_of, read, temp_dir, text, triangle, with_line,
};
use emg_krl_check::{KrlReport, ReadError, read_krl};
use emg_verify::ReferenceModel;

/// The shipped KR 16-2's checker, base `base_link`, tip `pen_tip`.
fn kr16_checker() -> ReferenceModel {
    ReferenceModel::from_urdf_file(
        &data_dir().join("robots/kr16_pen.urdf"),
        "base_link",
        "pen_tip",
    )
    .expect("the KR 16-2's checker")
}

/// A KRL program written by `emg job`: its `.src` and `.dat`, its plan and the `.src`'s path.
struct Exported {
    src: String,
    dat: String,
    plan: emg_job::JobFile,
    path: PathBuf,
}

/// `drawing` planned on the KR 16-2 by `emg job ... --export krl` (with `extra` arguments) into
/// `dir` as `drawing.job.json`.
fn exported(drawing: &Path, dir: &Path, extra: &[&str]) -> Exported {
    let plan = job_exported(
        drawing,
        ("kr16", "krl"),
        &dir.join("drawing.job.json"),
        extra,
    );
    let path = dir.join("drawing.src");
    Exported {
        src: read(&path),
        dat: read(&dir.join("drawing.dat")),
        plan,
        path,
    }
}

/// Checks what every program that reads back must show.
fn assert_reads_back(report: &KrlReport, plan: &emg_job::JobFile) {
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
fn the_house_program_reads_back_every_target_the_plans_configuration() {
    let dir = temp_dir("krl-house");
    let program = exported(&case("pen-drag-house.svg"), dir.path(), &[]);
    let report = read_krl(&program.src, &program.dat, &program.plan, &kr16_checker())
        .expect("the program reads back");
    eprintln!("{report:#?}");
    assert_reads_back(&report, &program.plan);
    // `emg check` reads it beside its plan.
    let run = emg(&["check", program.path.to_str().expect("utf-8 path")]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    assert!(text(&run.stdout).contains("KRL read back"));
}

/// A logo stroke whose path turns sharply where the plan's samples cut the turn within the
/// tolerance: the approximated corners pass the turn as closely as the samples do.
#[test]
fn the_cusped_logo_reads_back() {
    let dir = temp_dir("krl-cusp");
    let program = exported(&case("cusp-logo.svg"), dir.path(), &[]);
    let report = read_krl(&program.src, &program.dat, &program.plan, &kr16_checker())
        .expect("the program reads back");
    assert_reads_back(&report, &program.plan);
}

/// A small job whose program is kept word for word in `tests/data/kr16-triangle.src` and
/// `.dat`: any change of the writer shows there. `EMG_WRITE_GOLDEN=1` writes them again.
#[test]
fn a_small_job_writes_the_program_kept_word_for_word() {
    let dir = temp_dir("krl-golden");
    let program = exported(&triangle(dir.path()), dir.path(), &["--width", "0.05"]);
    assert!(
        !program
            .src
            .contains(dir.path().to_str().expect("utf-8 path"))
    );
    assert_golden(&program.src, "kr16-triangle.src");
    assert_golden(&program.dat, "kr16-triangle.dat");
    let report = read_krl(&program.src, &program.dat, &program.plan, &kr16_checker())
        .expect("the program reads back");
    assert_reads_back(&report, &program.plan);
    assert_eq!(report.drawn.stroke_parts, 1);
}

#[test]
fn krl_for_an_arm_of_another_vendor_is_refused_before_anything_is_planned() {
    assert_export_refused_before_planning("krl", &["irb120", "ur5e", "fr3"]);
}

/// `line` with the number after `key ` turned by `change`.
fn with_field(line: &str, key: &str, change: impl Fn(f64) -> String) -> String {
    let at = line.find(&format!(",{key} ")).expect("the field") + key.len() + 2;
    let end = at + line[at..].find(',').expect("the field's end");
    let value: f64 = line[at..end].parse().expect("a number");
    format!("{}{}{}", &line[..at], change(value), &line[end..])
}

#[test]
fn edits_of_a_program_are_refused_at_their_line() {
    let dir = temp_dir("krl-edits");
    let program = exported(&case("pen-drag-house.svg"), dir.path(), &[]);
    let checker = kr16_checker();
    let refused = |src: &str, dat: &str| -> ReadError {
        read_krl(src, dat, &program.plan, &checker).expect_err("an edited program is refused")
    };
    let (src, dat) = (&program.src, &program.dat);
    let stroke_move = line_of(src, |l| l.trim().starts_with("LIN ") && l.contains("C_DIS"));
    let point = src.lines().nth(stroke_move - 1).expect("the line")["  LIN ".len()..]
        .split_whitespace()
        .next()
        .expect("the point")
        .to_string();
    let declared = line_of(dat, |l| l.starts_with(&format!("DECL E6POS {point}=")));
    // A target moved by a millimetre.
    let moved = with_line(dat, declared, |l| {
        with_field(l, "Y", |y| format!("{:.4}", y + 1.0))
    });
    let error = refused(src, &moved);
    assert_eq!(error.line, stroke_move, "{error}");
    // A Status bit flipped: A5's.
    let flipped = with_line(dat, declared, |l| {
        with_field(l, "S", |s| format!("{}", s as u8 ^ 4))
    });
    let error = refused(src, &flipped);
    assert_eq!(error.line, stroke_move, "{error}");
    assert!(error.problem.contains("Status"), "{error}");
    // The tool never switched on for the first stroke part.
    let switch = line_of(src, |l| l.trim() == "$OUT[1]=TRUE");
    let unswitched = with_line(src, switch, |_| "  ; $OUT left out".to_string());
    let error = refused(&unswitched, dat);
    assert!(error.problem.contains("switches"), "{error}");
    // The tool a tenth of a millimetre off the pen's axis.
    let tool = line_of(dat, |l| l.starts_with("DECL FRAME EMG_TOOL"));
    let off_axis = with_line(dat, tool, |l| {
        with_field(l, "Y", |y| format!("{:.4}", y + 0.1))
    });
    let error = refused(src, &off_axis);
    assert!(error.problem.contains("$TOOL"), "{error}");
    // An approximation where the tool must stop: the last target of a stroke part.
    let off = switch
        + src
            .lines()
            .skip(switch)
            .position(|l| l.trim() == "$OUT[1]=FALSE")
            .expect("the tool off")
        + 1;
    let last = off - 1;
    let approximated = with_line(src, last, |l| format!("{l} C_DIS"));
    let error = refused(&approximated, dat);
    assert_eq!(error.line, last + 1, "{error}");
}
