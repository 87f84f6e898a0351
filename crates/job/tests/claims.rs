//! A program's claims are what its samples draw: the drawings of `../shared/cases/` that once
//! drew less than they claimed, planned and measured again by the independent checker, and
//! programs edited to claim more refused naming the stroke.

mod common;

use emg_io::Placement;
use emg_job::{JobCheckError, JobFile, SegmentKind, Shortfall, verify_job};
use emg_planner::Planner;
use emg_verify::ReferenceModel;

/// `drawing` of `../shared/cases/` placed as `placement` says, planned on `robot` as `emg job`
/// plans it.
fn planned(
    robot: &str,
    drawing: &str,
    placement: &Placement,
) -> (JobFile, Planner, ReferenceModel) {
    let (planner, timing, checker, file) = common::setup(robot);
    let job = common::drawing(planner.robot(), &common::case(drawing), placement);
    (
        common::plan(&planner, &timing, &file, &job),
        planner,
        checker,
    )
}

/// The program's claims equal what the checker measures of its samples.
fn claims_are_measured(program: &JobFile, planner: &Planner, checker: &ReferenceModel) {
    let check = verify_job(program, checker, planner.robot().joint_names())
        .unwrap_or_else(|e| panic!("{e}"));
    let summary = &program.summary;
    assert!(
        (check.drawn_m - summary.drawn_m).abs() < 1e-6,
        "the samples draw {} m, the program claims {} m",
        check.drawn_m,
        summary.drawn_m
    );
    assert_eq!(check.whole_strokes, summary.complete + summary.resumed);
    for stroke in &program.strokes {
        // Gaps shorter than the slack are neither drawn nor listed: one at each end of a part.
        let undrawn: f64 = stroke.unreached.iter().map(|u| u.to_s - u.from_s).sum();
        let slack = emg_job::COVERAGE_SLACK_M * (2 * stroke.parts) as f64 + 1e-6;
        assert!(
            (stroke.drawn_m + undrawn - stroke.length_m).abs() < slack,
            "stroke {}: {} m drawn and {undrawn} m unreached of {} m",
            stroke.stroke,
            stroke.drawn_m,
            stroke.length_m
        );
    }
}

#[test]
fn a_small_closed_circle_is_drawn_round_not_claimed_at_a_standstill() {
    let placement = Placement {
        origin_m: [0.45, 0.25, 0.25],
        ..Placement::default()
    };
    let (program, planner, checker) = planned("fr3", "small-circle.svg", &placement);
    claims_are_measured(&program, &planner, &checker);
    let speed = planner.config().rollout.speed_m_per_s;
    for report in &program.strokes {
        // Each stroke is drawn at no more than the tool's speed: its segments last at least its
        // length drawn over that speed.
        let pen_down_s: f64 = program
            .segments
            .iter()
            .filter(
                |s| matches!(s.kind, SegmentKind::Stroke { stroke, .. } if stroke == report.stroke),
            )
            .map(|s| s.end_s - s.start_s)
            .sum();
        assert!(
            pen_down_s >= report.drawn_m / speed,
            "stroke {}: {} m drawn in {pen_down_s} s",
            report.stroke,
            report.drawn_m
        );
    }
    // The circle (the shorter stroke, 47 mm round) is drawn whole.
    let circle = program
        .strokes
        .iter()
        .min_by(|a, b| a.length_m.total_cmp(&b.length_m))
        .expect("two strokes");
    assert!(
        (circle.length_m - 0.0471).abs() < 1e-3,
        "{}",
        circle.length_m
    );
    assert!(circle.unreached.is_empty() && circle.drawn_m > circle.length_m - 1e-3);
}

#[test]
fn the_ur5e_house_is_drawn_whole_as_it_claims() {
    let (program, planner, checker) = planned("ur5e", "house.svg", &Placement::default());
    claims_are_measured(&program, &planner, &checker);
    // The walls (the longest stroke) were once claimed whole with a sixth of them drawn.
    let walls = program
        .strokes
        .iter()
        .max_by(|a, b| a.length_m.total_cmp(&b.length_m))
        .expect("strokes");
    assert!(
        walls.unreached.is_empty() && walls.drawn_m > walls.length_m - 1e-3,
        "{walls:?}"
    );
}

#[test]
fn a_job_left_short_lists_what_it_misses_and_inflated_claims_are_refused() {
    // The house twice its size, far out on the UR5e's right: a stroke out of reach.
    let placement = Placement {
        origin_m: [0.8, 0.2, 0.2],
        width_m: Some(0.4),
        ..Placement::default()
    };
    let (program, planner, checker) = planned("ur5e", "house.svg", &placement);
    claims_are_measured(&program, &planner, &checker);
    let short = program
        .strokes
        .iter()
        .position(|s| !s.unreached.is_empty())
        .expect("a stroke left short");
    assert!(program.summary.short >= 1);
    let joints = planner.robot().joint_names();
    let refused = |edited: &JobFile| verify_job(edited, &checker, joints).unwrap_err();

    // A stroke claiming a millimetre more than its samples draw.
    let mut inflated = program.clone();
    inflated.strokes[short].drawn_m += 1e-3;
    let error = refused(&inflated);
    assert!(
        matches!(&error, JobCheckError::Claim { stroke, .. } if *stroke == program.strokes[short].stroke),
        "{error}"
    );
    assert!(
        error.to_string().contains("m drawn; its samples draw"),
        "{error}"
    );
    // Each undrawn stretch has its cause: the constraint that stopped the arm where it starts,
    // why no motion starts there, or the searches spent before it, the first of a stroke never
    // the last; a program without them is refused.
    for stroke in &program.strokes {
        assert_eq!(stroke.unreached_causes.len(), stroke.unreached.len());
        for (place, cause) in stroke.unreached_causes.iter().enumerate() {
            let searched = matches!(cause, Shortfall::Reach { .. } | Shortfall::NoStart { .. });
            assert!(
                searched || (place > 0 && *cause == Shortfall::NotSearched),
                "stroke {}: {cause}",
                stroke.stroke
            );
        }
    }
    let mut causeless = program.clone();
    causeless.strokes[short].unreached_causes.clear();
    assert!(refused(&causeless).to_string().contains("causes"));
    // A stroke whose undrawn stretch is not listed.
    let mut hidden = program.clone();
    hidden.strokes[short].unreached.clear();
    hidden.strokes[short].unreached_at.clear();
    hidden.strokes[short].unreached_causes.clear();
    let error = refused(&hidden);
    assert!(
        error.to_string().contains("not listed as unreached"),
        "{error}"
    );
    // A summary counting one more stroke whole, or claiming more length.
    let mut counted = program.clone();
    counted.summary.complete += 1;
    counted.summary.short -= 1;
    assert!(matches!(refused(&counted), JobCheckError::Summary(_)));
    let mut longer = program.clone();
    longer.summary.drawn_m += 0.01;
    assert!(matches!(refused(&longer), JobCheckError::Summary(_)));
    // A stroke claiming a longer path than the one it carries.
    let mut stretched = program.clone();
    stretched.strokes[1].length_m += 0.01;
    assert!(refused(&stretched).to_string().contains("claims a length"));
    // A stroke part said to start elsewhere along its stroke.
    let mut shifted = program.clone();
    let part = shifted
        .segments
        .iter_mut()
        .find_map(|s| match &mut s.kind {
            SegmentKind::Stroke { from_s, .. } => Some(from_s),
            _ => None,
        })
        .expect("a stroke part");
    *part += 0.005;
    let error = refused(&shifted);
    assert!(
        error.to_string().contains("is not the stroke's stretch"),
        "{error}"
    );
}

/// Every corner of each stroke that its program claims drawn lies within the tolerance of a
/// pen-down sample of that stroke, measured with the checker's kinematics: a corner the pen
/// turns back short of is undrawn, whatever the claim.
fn every_claimed_corner_is_drawn(program: &JobFile, checker: &ReferenceModel) {
    let points = program.points();
    let tolerance = program.constraints.line_tolerance_m;
    for (place, report) in program.strokes.iter().enumerate() {
        let path = emg_control::Path::new(report.path.clone()).expect("the stroke's path");
        let tips = pen_down_tips(program, &points, report.stroke, checker);
        for corner in path.corners_m() {
            let claimed_undrawn = report
                .unreached
                .iter()
                .any(|u| corner >= u.from_s - 1e-6 && corner <= u.to_s + 1e-6);
            if claimed_undrawn {
                continue;
            }
            let vertex = path.point_at(corner);
            let nearest = tips
                .iter()
                .map(|tip| (tip - vertex).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(
                nearest <= tolerance + 1e-6,
                "stroke {place}: the corner {corner:.4} m along it is claimed drawn, but no \
                 sample comes nearer it than {:.3} mm",
                nearest * 1e3
            );
        }
    }
}

/// The tool tip of every pen-down sample of `stroke` in `program`, by the checker's kinematics.
fn pen_down_tips(
    program: &JobFile,
    points: &[emg_io::JointTrajectoryPoint],
    stroke: usize,
    checker: &ReferenceModel,
) -> Vec<emg_kinematics::Vec3> {
    program
        .segments
        .iter()
        .filter(|s| matches!(s.kind, SegmentKind::Stroke { stroke: k, .. } if k == stroke))
        .flat_map(|s| {
            points.iter().filter(move |p| {
                let t = p.time_from_start.seconds();
                t >= s.start_s - 1e-9 && t <= s.end_s + 1e-9
            })
        })
        .map(|p| {
            let mut q = emg_verify::Joints::zeros();
            q.as_mut_slice()[..p.positions.len()].copy_from_slice(&p.positions);
            checker.tcp_pose(&q).0
        })
        .collect()
}

/// The distance from `p` to the polyline through `vertices`.
fn polyline_distance(p: &emg_kinematics::Vec3, vertices: &[emg_kinematics::Vec3]) -> f64 {
    vertices
        .windows(2)
        .map(|w| {
            let ab = w[1] - w[0];
            let t = ((p - w[0]).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            (p - (w[0] + ab * t)).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn rounded_corners_keep_the_pen_within_the_tolerance_of_the_drawing_as_given() {
    // Lettering as a single-stroke font gives it: a curve flattened into 24° turns, a W of
    // sharp turns, and a closed star of 144° turns.
    let arc: Vec<String> = (0..=12)
        .map(|k| {
            let a = (k as f64 * 24.0).to_radians();
            format!(
                "{:.4},{:.4}",
                10.0 + 8.0 * libm::cos(a),
                10.0 + 8.0 * libm::sin(a)
            )
        })
        .collect();
    let star: Vec<String> = (0..5)
        .map(|k| {
            let a = (90.0 + k as f64 * 144.0).to_radians();
            format!(
                "{:.4},{:.4}",
                60.0 + 8.0 * libm::cos(a),
                10.0 + 8.0 * libm::sin(a)
            )
        })
        .collect();
    // A round letter of a serif font: a loop of 2.3 mm radius gone round twice, 0.4 mm inside
    // itself the second time (rounded, its first timing once looked for the path's nearest
    // point on the other turn and cut the stroke at its start).
    let double_loop: Vec<String> = (0..=24)
        .map(|k| {
            let (a, r) = (
                (k as f64 * 30.0).to_radians(),
                if k <= 12 { 1.4 } else { 1.16 },
            );
            format!(
                "{:.4},{:.4}",
                48.0 + r * libm::cos(a),
                10.0 + r * libm::sin(a)
            )
        })
        .collect();
    let svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 72 20">
        <polyline fill="none" stroke="black" points="{}"/>
        <polyline fill="none" stroke="black" points="24,2 28,18 32,6 36,18 40,2"/>
        <polyline fill="none" stroke="black" points="{}"/>
        <polygon fill="none" stroke="black" points="{}"/>
        </svg>"#,
        arc.join(" "),
        double_loop.join(" "),
        star.join(" ")
    );
    let dir = std::env::temp_dir().join(format!("emg-lettering-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary directory");
    let file = dir.join("lettering.svg");
    std::fs::write(&file, svg).expect("the drawing is written");
    let (planner, timing, checker, robot_file) = common::setup("fr3");
    let placement = Placement {
        width_m: Some(0.12),
        ..Placement::default()
    };
    let tolerance = emg_job::DrawingTolerance::new(emg_job::JOB_TOLERANCE_M, 1.25e-4).unwrap();
    let sharp = emg_job::DrawingTolerance::new(emg_job::JOB_TOLERANCE_M, 0.0).unwrap();
    let read = |tolerance: &emg_job::DrawingTolerance| {
        let drawing = emg_io::read_svg_file(&file, &placement, &tolerance.svg_options())
            .expect("the drawing");
        tolerance
            .job(drawing, planner.robot())
            .expect("a valid job")
    };
    let (job, at_corners) = (read(&tolerance), read(&sharp));
    // The polylines exactly: no joint made smooth, no corner rounded.
    let exact = emg_io::SvgOptions {
        smooth_join_deg: 0.0,
        ..sharp.svg_options()
    };
    let as_given = emg_io::read_svg_file(&file, &placement, &exact).expect("the drawing");
    std::fs::remove_dir_all(&dir).ok();
    let program = common::plan(&planner, &timing, &robot_file, &job);
    claims_are_measured(&program, &planner, &checker);
    every_claimed_corner_is_drawn(&program, &checker);
    assert!(
        program.summary.drawn_m > 0.99 * program.summary.total_m,
        "{} m of {} m drawn",
        program.summary.drawn_m,
        program.summary.total_m
    );
    assert_eq!(
        program.constraints.line_tolerance_m,
        tolerance.line_m - tolerance.corner_m
    );
    // Against the drawing as given (its polylines with their corners): every pen-down sample
    // within the line tolerance, and every vertex of a stroke drawn whole within it of one.
    let points = program.points();
    for report in &program.strokes {
        let given = &as_given.strokes[report.stroke];
        let vertices: Vec<emg_kinematics::Vec3> = std::iter::once(given.start)
            .chain(given.segments.iter().map(|segment| match segment {
                emg_control::SegmentSpec::Line { to } => *to,
                other => panic!("a polyline has only lines: {other:?}"),
            }))
            .map(emg_kinematics::Vec3::from)
            .collect();
        let tips = pen_down_tips(&program, &points, report.stroke, &checker);
        let farthest = tips
            .iter()
            .map(|tip| polyline_distance(tip, &vertices))
            .fold(0.0, f64::max);
        assert!(
            farthest <= tolerance.line_m + 1e-6,
            "stroke {}: a pen-down sample {:.3} mm from the drawing",
            report.stroke,
            farthest * 1e3
        );
        if report.unreached.is_empty() {
            for vertex in &vertices {
                let nearest = tips
                    .iter()
                    .map(|tip| (tip - vertex).norm())
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    nearest <= tolerance.line_m + 1e-6,
                    "stroke {}: no sample within {:.3} mm of a vertex",
                    report.stroke,
                    nearest * 1e3
                );
            }
        }
    }
    // Rounded, the lettering is drawn faster than with every corner passed at rest.
    let at_rest = common::plan(&planner, &timing, &robot_file, &at_corners);
    assert!(
        program.summary.pen_down_s < 0.9 * at_rest.summary.pen_down_s,
        "{} s pen down rounded, {} s at rest",
        program.summary.pen_down_s,
        at_rest.summary.pen_down_s
    );
}

#[test]
fn a_zigzag_of_reversals_is_drawn_to_every_corner_it_claims() {
    // 173° reversals: a sample near one leg once counted for the other, so that the pen turned
    // back 4.65 mm short of a corner while the program claimed the stroke whole.
    let placement = Placement {
        width_m: Some(0.1),
        ..Placement::default()
    };
    let (program, planner, checker) = planned("fr3", "zigzag.svg", &placement);
    claims_are_measured(&program, &planner, &checker);
    every_claimed_corner_is_drawn(&program, &checker);
}

#[test]
fn a_path_that_retraces_itself_is_planned_and_drawn_as_it_claims() {
    // A map outline's short back-and-forth segments: a small closed stroke that goes out and
    // back over itself. The progress once jumped back along the retraced stretch, the motion
    // went round it again and again, and the timing's rests came out of order (a panic).
    let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 40 40">
        <path fill="none" stroke="black"
              d="M5,5 l10,0 l-6,0.2 l8,0.4 l0.5,6 l-0.5,-3 l-12,2 l-4,-5.6 l4,0 l-4,0 z"/>
        <path fill="none" stroke="black" d="M5,30 l30,0 l-30,0.3 l30,0.3"/>
    </svg>"#;
    let dir = std::env::temp_dir().join(format!("emg-retrace-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary directory");
    let file = dir.join("retrace.svg");
    std::fs::write(&file, svg).expect("the drawing is written");
    let (planner, timing, checker, robot_file) = common::setup("fr3");
    let placement = Placement {
        width_m: Some(0.1),
        ..Placement::default()
    };
    let job = common::drawing(planner.robot(), &file, &placement);
    let program = common::plan(&planner, &timing, &robot_file, &job);
    std::fs::remove_dir_all(&dir).ok();
    claims_are_measured(&program, &planner, &checker);
    every_claimed_corner_is_drawn(&program, &checker);
    assert!(
        program.summary.drawn_m > 0.9 * program.summary.total_m,
        "{} m of {} m drawn",
        program.summary.drawn_m,
        program.summary.total_m
    );
}

#[test]
fn pen_up_moves_keep_clear_of_the_part_and_a_program_that_does_not_is_refused() {
    // The blended pen-up move between the two strokes once sagged 0.12 mm into the part and
    // slid 32 mm across it, and the check passed it.
    let (program, planner, checker) = planned("fr3", "pen-drag-house.svg", &Placement::default());
    claims_are_measured(&program, &planner, &checker);
    // The same motion said to lift 10 cm: its moves come nearer the part than half of that
    // away from their lifts and set-downs.
    let mut higher = program.clone();
    higher.settings.lift_m = Some(0.1);
    match verify_job(&higher, &checker, planner.robot().joint_names()) {
        Err(JobCheckError::PenUp {
            segment,
            height_m,
            off_m,
            clearance_m,
            ..
        }) => {
            assert!(!matches!(
                higher.segments[segment].kind,
                SegmentKind::Stroke { .. }
            ));
            assert!(height_m < clearance_m && off_m > emg_job::LIFT_CONE_RUN * height_m);
            assert!((clearance_m - 0.05).abs() < 1e-12);
        }
        other => panic!("a program whose moves skim the part passes: {other:?}"),
    }
}

#[test]
fn a_timed_motion_cut_short_of_its_plan_is_resumed_where_its_samples_stop() {
    // The figure eight of the Hershey simplex font (the `8` of a line of digits 0.2 m wide,
    // one polyline crossing itself), its corners rounded within 0.125 mm: a timed sample of
    // its one planned motion left the tolerance at a rounded corner and cut the motion after
    // 19 mm of 34 mm, and the rest was once listed undrawn ("the timed motion stops before it").
    let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 450 34">
        <polyline fill="none" stroke="black" points="166,29 163,28 162,26 162,24 163,22 165,21
        169,20 172,19 174,17 175,15 175,12 174,10 173,9 170,8 166,8 163,9 162,10 161,12 161,15
        162,17 164,19 167,20 171,21 173,22 174,24 174,26 173,28 170,29 166,29"/>
        </svg>"#;
    let (planner, timing, checker, robot_file) = common::setup("fr3");
    // Where and how large the line of digits put it.
    let placement = Placement {
        origin_m: [0.449_330_357_142_857, 0.025_446_428_571_428, 0.25],
        width_m: Some(0.006_25),
        ..Placement::default()
    };
    let tolerance = emg_job::DrawingTolerance::new(emg_job::JOB_TOLERANCE_M, 1.25e-4).unwrap();
    let drawing = emg_io::read_svg(svg, &placement, &tolerance.svg_options()).expect("the drawing");
    let job = tolerance
        .job(drawing, planner.robot())
        .expect("a valid job");
    let program = common::plan(&planner, &timing, &robot_file, &job);
    claims_are_measured(&program, &planner, &checker);
    let stroke = &program.strokes[0];
    assert!(
        stroke.unreached.is_empty() && stroke.unreached_causes.is_empty(),
        "{:?}",
        stroke.unreached_causes
    );
    // Drawn in more than the one part planned: resumed where the cut part's samples stop.
    assert!(stroke.parts > 1, "{} parts", stroke.parts);
}
