//! The native URScript programs `emg job --export urscript` writes for the UR5e, read back by an
//! independent reader (`common/ur_reader.rs`: its own parser, the URScript manual's motion
//! semantics, the UR5e's closed-form inverse kinematics, the checker's kinematics and
//! clearances) and checked against the job's plan; first the reader itself on programs and
//! poses made by hand.

mod common;
#[path = "common/ur_reader.rs"]
mod ur_reader;

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use common::{data_dir, emg, read, temp_dir, text};
use emg_kinematics::Vec3;
use emg_verify::ReferenceModel;
use ur_reader::{
    PATH_STEP_M, Piece, Pose, ReadReport, Rotation, checker_tcp, movep_path, parse_program,
    read_program, ur5e_flange, ur5e_inverse,
};

/// The shipped UR5e's checker, base `base_link`, tip `pen_tip`.
fn ur5e_checker() -> ReferenceModel {
    ReferenceModel::from_urdf_file(
        &data_dir().join("robots/ur5e_pen.urdf"),
        "base_link",
        "pen_tip",
    )
    .expect("the UR5e's checker")
}

/// The shipped pen's TCP in the flange frame: 0.2034 m along its z-axis.
fn pen() -> Pose {
    Pose::from_ur(&[0.0, 0.0, 0.2034, 0.0, 0.0, 0.0])
}

/// A small deterministic stream of numbers in [0, 1) (xorshift64*).
struct Stream(u64);

impl Stream {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn between(&mut self, low: f64, high: f64) -> f64 {
        low + (high - low) * self.next()
    }
}

#[test]
fn the_closed_form_inverse_gives_eight_configurations_of_the_checkers_pose() {
    let checker = ur5e_checker();
    let mut stream = Stream(0x0005_E5EE_D0FA_11CE);
    let mut eight = 0;
    for _ in 0..200 {
        let q: [f64; 6] = std::array::from_fn(|i| {
            // The elbow within ±π, as its limits; the others over a full turn and more.
            let span = if i == 2 { 3.0 } else { 6.0 };
            stream.between(-span, span)
        });
        let tcp = checker_tcp(&checker, &q);
        // The DH chain and the pen are the checker's tip.
        let (distance, angle) = ur5e_flange(&q).then(&pen()).difference(&tcp);
        assert!(
            distance < 1e-12 && angle < 1e-12,
            "{q:?}: {distance}, {angle}"
        );
        let flange = tcp.then(&pen().inverse());
        let solutions = ur5e_inverse(&flange);
        // Near a stretched elbow the other shoulder's or wrist's arm may fall short: 8
        // solutions, else an even number of them.
        assert!(
            [2, 4, 6, 8].contains(&solutions.len()),
            "{q:?}: {solutions:?}"
        );
        eight += usize::from(solutions.len() == 8);
        for (i, a) in solutions.iter().enumerate() {
            let (distance, angle) = checker_tcp(&checker, &a.q).difference(&tcp);
            assert!(distance < 1e-9 && angle < 1e-9, "{q:?} → {a:?}");
            for b in &solutions[i + 1..] {
                assert_ne!(a.branch, b.branch);
            }
        }
        let original = solutions.iter().any(|s| {
            s.q.iter()
                .zip(&q)
                .all(|(x, y)| ur_reader::wrap(x - y).abs() < 1e-7)
        });
        assert!(original, "{q:?} is not among {solutions:?}");
    }
    assert!(eight >= 100, "8 solutions at {eight} of 200 configurations");
}

#[test]
fn rotation_vectors_round_trip_and_slerp_turns_evenly() {
    let mut stream = Stream(0x0000_0A11_CE5E_ED00);
    for k in 0..500 {
        let axis = Vec3::new(
            stream.between(-1.0, 1.0),
            stream.between(-1.0, 1.0),
            stream.between(-1.0, 1.0),
        )
        .normalize();
        // Angles across (0, π), the last ones within 1e-9 of a half turn.
        let angle = if k < 450 {
            stream.between(1e-6, PI - 1e-3)
        } else {
            PI - stream.between(0.0, 1e-9)
        };
        let rotation = Rotation::from_rotation_vector(&(axis * angle));
        let m = rotation.0;
        let orthonormal = rotation.transpose().then(&rotation);
        for (r, row) in orthonormal.0.iter().enumerate() {
            for (c, value) in row.iter().enumerate() {
                assert!((value - f64::from(u8::from(r == c))).abs() < 1e-14);
            }
        }
        assert!((rotation.apply(&axis) - axis).norm() < 1e-14);
        let back = rotation.rotation_vector();
        if angle < PI - 1e-6 {
            assert!((back - axis * angle).norm() < 1e-12, "{angle}: {back:?}");
        } else {
            // At a half turn ±axis are the same rotation.
            assert!((back.norm() - angle).abs() < 1e-9);
            let again = Rotation::from_rotation_vector(&back).0;
            for r in 0..3 {
                for c in 0..3 {
                    assert!((again[r][c] - m[r][c]).abs() < 1e-8, "{angle}");
                }
            }
        }
        // A pose in URScript's form and back.
        let values = [0.3, -0.2, 0.1, back.x, back.y, back.z];
        let pose = Pose::from_ur(&values);
        let (distance, turn) = Pose::from_ur(&pose.to_ur()).difference(&pose);
        assert!(distance == 0.0 && turn < 1e-9);
        // Slerp from a random rotation to this one: the ends, and the turn shared evenly.
        let start = Rotation::from_rotation_vector(&Vec3::new(
            stream.between(-1.0, 1.0),
            stream.between(-1.0, 1.0),
            stream.between(-1.0, 1.0),
        ));
        let whole = start.angle_to(&rotation);
        assert!(start.slerp(&rotation, 0.0).angle_to(&start) < 1e-12);
        if whole < PI - 1e-3 {
            assert!(start.slerp(&rotation, 1.0).angle_to(&rotation) < 1e-12);
            for s in [0.25, 0.5, 0.9] {
                let between = start.slerp(&rotation, s);
                assert!((start.angle_to(&between) - s * whole).abs() < 1e-12);
                assert!((between.angle_to(&rotation) - (1.0 - s) * whole).abs() < 1e-12);
            }
        }
    }
}

/// A pose at `(x, y, z)` turned `angle` about z from the pen pointing down.
fn down(x: f64, y: f64, z: f64, angle: f64) -> Pose {
    Pose {
        position: Vec3::new(x, y, z),
        rotation: Rotation::from_rotation_vector(&Vec3::new(PI, 0.0, 0.0))
            .then(&Rotation::from_rotation_vector(&Vec3::new(0.0, 0.0, angle))),
    }
}

#[test]
fn a_movep_run_blends_its_corners_on_tangent_circular_arcs() {
    let start = down(0.0, 0.0, 0.1, 0.0);
    // A left turn of 90° blended 20 mm, a right turn of 90° blended 30 mm, a turn of 45°
    // blended 10 mm, and the run's end.
    let corner = down(0.1, 0.0, 0.1, 0.2);
    let second = down(0.1, 0.1, 0.1, 0.4);
    let third = down(0.2, 0.1, 0.1, 0.1);
    let end = down(0.3, 0.2, 0.1, -0.3);
    let targets = [
        (corner, 0.02, 11),
        (second, 0.03, 12),
        (third, 0.01, 13),
        (end, 0.0, 14),
    ];
    let pieces = movep_path(&start, &targets).expect("a valid run");
    let lines: Vec<usize> = pieces.iter().map(|(_, line)| *line).collect();
    assert_eq!(lines, [11, 11, 12, 12, 13, 13, 14]);
    // Each blend: its centre, radius and ends as the geometry of the corner gives them.
    let expect_arc = |piece: &Piece, centre: Vec3, radius: f64, from: Vec3, to: Vec3| {
        let Piece::Arc {
            centre: c,
            sweep_rad,
            ..
        } = piece
        else {
            panic!("{piece:?} is not an arc");
        };
        assert!((c - centre).norm() < 1e-12, "{c:?} vs {centre:?}");
        assert!((piece.at(0.0).position - from).norm() < 1e-12);
        assert!((piece.at(1.0).position - to).norm() < 1e-12);
        for sample in piece.samples() {
            assert!(((sample.position - centre).norm() - radius).abs() < 1e-12);
        }
        assert!((piece.extent().0 - radius * sweep_rad).abs() < 1e-12);
    };
    expect_arc(
        &pieces[1].0,
        Vec3::new(0.08, 0.02, 0.1),
        0.02,
        Vec3::new(0.08, 0.0, 0.1),
        Vec3::new(0.1, 0.02, 0.1),
    );
    expect_arc(
        &pieces[3].0,
        Vec3::new(0.13, 0.07, 0.1),
        0.03,
        Vec3::new(0.1, 0.07, 0.1),
        Vec3::new(0.13, 0.1, 0.1),
    );
    // The 45° corner at (0.2, 0.1): the circle's radius is r·cot(22.5°), its centre on the
    // inner side of the incoming line at the tangent point 10 mm before the corner.
    let radius = 0.01 / libm_free_tan(PI / 8.0);
    expect_arc(
        &pieces[5].0,
        Vec3::new(0.19, 0.1 + radius, 0.1),
        radius,
        Vec3::new(0.19, 0.1, 0.1),
        Vec3::new(0.2, 0.1, 0.1) + Vec3::new(1.0, 1.0, 0.0).normalize() * 0.01,
    );
    // The orientation at a blend's ends is the lines' slerp there, and it turns continuously.
    let on_line = |a: &Pose, b: &Pose, s: f64| a.rotation.slerp(&b.rotation, s);
    let blend = &pieces[1].0;
    assert!(
        blend
            .at(0.0)
            .rotation
            .angle_to(&on_line(&start, &corner, 0.8))
            < 1e-12
    );
    assert!(
        blend
            .at(1.0)
            .rotation
            .angle_to(&on_line(&corner, &second, 0.2))
            < 1e-12
    );
    // The path is continuous and sampled at most 0.1 mm apart.
    let mut previous = start;
    for (piece, _) in &pieces {
        for sample in piece.samples() {
            let (distance, turn) = sample.difference(&previous);
            assert!(distance <= PATH_STEP_M + 1e-12 && turn <= 1e-3 + 1e-12);
            previous = sample;
        }
    }
    assert!(previous.difference(&end).0 < 1e-12);
    // A radius over half of a line is refused at its line, and so is a blend at the end.
    let too_wide = [(corner, 0.051, 21), (second, 0.0, 22)];
    assert_eq!(
        movep_path(&start, &too_wide).expect_err("too wide").line,
        21
    );
    let blended_end = [(corner, 0.01, 31), (second, 0.01, 32)];
    assert_eq!(
        movep_path(&start, &blended_end)
            .expect_err("blended end")
            .line,
        32
    );
}

/// tan(x) from the run's own sine and cosine construction: the ratio of a rotation's entries.
fn libm_free_tan(x: f64) -> f64 {
    let m = Rotation::from_rotation_vector(&Vec3::new(0.0, 0.0, x)).0;
    m[1][0] / m[0][0]
}

/// A program in the grammar, by hand.
const HAND_PROGRAM: &str = "# made by hand
def emg_job():
  set_tcp(p[0.0, 0.0, 0.2034, 0.0, 0.0, 0.0])
  set_standard_digital_out(0, False)  # the pen up
  home = [0.0, -1.5707963267948966, 1.5707963267948966, -1.5707963267948966, -1.5707963267948966, 0.0]
  actual = get_actual_joint_positions()
  joint = 0
  while joint < 6:
    if norm(actual[joint] - home[joint]) > 0.01:
      popup(\"not at the home # of the job\", title=\"emg\", error=True, blocking=True)
      halt
    end
    joint = joint + 1
  end
  movej([0.1, -1.5, 1.5, -1.5, -1.5, 0.0], a=1.4, v=1.05)
  movel(p[-0.4, -0.2, 0.1, 3.141592653589793, 0.0, 0.0], a=1.2, v=0.25)
  set_standard_digital_out(0, True)
  movep(p[-0.4, -0.1, 0.1, 3.141592653589793, 0.0, 0.0], a=1.2, v=0.25, r=0.002)
  movep(p[-0.3, -0.1, 0.1, 3.141592653589793, -1.2e-5, 0.0], a=1.2, v=0.25, r=0.0)
  set_standard_digital_out(0, False)
  sleep(0.1)
end
# after the program
";

#[test]
fn the_parser_reads_the_grammar_and_names_the_line_of_anything_else() {
    use ur_reader::Statement;
    let program = parse_program(HAND_PROGRAM).expect("the hand-made program parses");
    let kinds: Vec<(usize, &str)> = program
        .statements
        .iter()
        .map(|(line, s)| {
            let kind = match s {
                Statement::SetTcp(_) => "tcp",
                Statement::DigitalOut { level: true, .. } => "on",
                Statement::DigitalOut { level: false, .. } => "off",
                Statement::HomeCheck { tolerance_rad, .. } => {
                    assert_eq!(*tolerance_rad, 0.01);
                    "home"
                }
                Statement::MoveJ { .. } => "movej",
                Statement::MoveL { .. } => "movel",
                Statement::MoveP { radius_m, .. } => {
                    assert!(*radius_m == 0.002 || *radius_m == 0.0);
                    "movep"
                }
                Statement::Sleep => "sleep",
            };
            (*line, kind)
        })
        .collect();
    assert_eq!(
        kinds,
        [
            (3, "tcp"),
            (4, "off"),
            (5, "home"),
            (15, "movej"),
            (16, "movel"),
            (17, "on"),
            (18, "movep"),
            (19, "movep"),
            (20, "off"),
            (21, "sleep"),
        ]
    );
    assert_eq!(program.code_lines, 21);
    // Each change below breaks line `line` of the program.
    for (line, from, to) in [
        (15, "movej([0.1, -1.5,", "movej([-1.5,"),
        (15, "a=1.4", "a=-1.4"),
        (16, "movel(", "servoj("),
        (18, ", r=0.002", ""),
        (19, "-1.2e-5", "1.2e-5e"),
        (9, "> 0.01", "> 0.0"),
        (11, "halt", "stop"),
        (21, "sleep(0.1)", "sleep(0.1"),
        (
            22,
            "end\n# after",
            "end\nmovej([0, 0, 0, 0, 0, 0], a=1, v=1)\n# after",
        ),
    ] {
        let broken = HAND_PROGRAM.replacen(from, to, 1);
        assert_ne!(broken, HAND_PROGRAM);
        let error = parse_program(&broken).expect_err(to);
        let expected = if line == 22 { 23 } else { line };
        assert_eq!(error.line, expected, "{from} → {to}: {error}");
    }
    let unclosed = HAND_PROGRAM.replace("  sleep(0.1)\nend\n", "  sleep(0.1)\n");
    assert_eq!(parse_program(&unclosed).expect_err("unclosed").line, 0);
}

/// A drawing of `../shared/cases/`.
fn case(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/cases")
        .join(name)
}

/// `drawing` planned on the UR5e by `emg job ... --export urscript` (with `extra` arguments)
/// into `dir`: the program's script and its plan.
fn exported(drawing: &Path, dir: &Path, extra: &[&str]) -> (String, emg_job::JobFile) {
    let out = dir.join("house.json");
    let mut args = vec![
        "job",
        drawing.to_str().expect("utf-8 path"),
        "--robot",
        "ur5e",
        "--out",
        out.to_str().expect("utf-8 path"),
        "--export",
        "urscript",
    ];
    args.extend_from_slice(extra);
    let run = emg(&args);
    assert!(
        run.status.success(),
        "emg job failed:\n{}\n{}",
        text(&run.stdout),
        text(&run.stderr)
    );
    let script = read(&out.with_extension("script"));
    let plan = emg_job::JobFile::parse(&read(&out)).expect("the plan parses");
    (script, plan)
}

/// Reads `script` against `plan`, printing the report.
fn read_back(script: &str, plan: &emg_job::JobFile) -> Result<ReadReport, ur_reader::ReadError> {
    let started = std::time::Instant::now();
    let report = read_program(script, plan, &ur5e_checker(), true);
    eprintln!(
        "read in {:.1} s: {report:#?}",
        started.elapsed().as_secs_f64()
    );
    report
}

/// Checks what every program that reads back must show.
fn assert_reads_back(report: &ReadReport, plan: &emg_job::JobFile) {
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
    let program = parse_program(&script).expect("the program parses");
    // The longest run of movep lines: its middle target, moved 1 mm across the stroke (in
    // the plane of the neighbouring targets' direction and the tool axis, perpendicular to
    // both).
    let mut runs: Vec<Vec<(usize, Pose)>> = Vec::new();
    let mut previous_line = 0;
    for (line, statement) in &program.statements {
        if let ur_reader::Statement::MoveP { pose, .. } = statement {
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
        let error = read_program(edited, &plan, &checker, on_level).expect_err("refused");
        assert_eq!(error.line, line, "{error}");
        assert!(error.problem.contains(why), "{error}");
    };
    // A movej target 1 µrad off the plan.
    let movej = find(0, "movej(");
    let bent = lines[movej - 1].replacen("movej([", "movej([0.000001 + ", 1);
    let program = parse_program(&with_line(&script, movej, &bent));
    assert!(program.is_err(), "an expression is no number");
    let ur_reader::Statement::MoveJ { q } = parse_program(&script)
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
    read_program(&swapped, &plan, &checker, false).unwrap_or_else(|e| panic!("{e}"));
    refused_at(
        &swapped,
        find(0, "set_standard_digital_out("),
        true,
        "the tool switches on before the first move",
    );
}
