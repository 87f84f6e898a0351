//! Jobs end to end: a real line-art icon (lucide-static 1.62.0's `pencil`, vendored with the
//! SVG reader's tests) planned on the FR3 and on the UR5e, its program re-checked segment by
//! segment by the independent checker; the order stage; wrong jobs refused naming what is wrong.

mod common;

use std::path::PathBuf;

use emg_io::{Placement, SvgOptions, read_svg_file};
use emg_job::{Job, JobError, SegmentKind, plan_job, verify_job};
use emg_kinematics::Robot;
use emg_planner::PlanRequest;

fn icon(name: &str) -> PathBuf {
    common::workspace().join(format!("crates/io/tests/data/icons/{name}.svg"))
}

fn icon_job(robot: &Robot, name: &str, placement: &Placement) -> Job {
    let drawing = read_svg_file(&icon(name), placement, &SvgOptions::default()).expect("icon");
    Job::from_strokes(drawing.strokes, robot).expect("a valid job")
}

fn plans_and_checks_the_pencil_icon(name: &str) {
    let (planner, timing, checker, file) = common::setup(name);
    let job = icon_job(planner.robot(), "pencil", &Placement::default());
    let program = common::plan(&planner, &timing, &file, &job);
    let summary = &program.summary;
    assert_eq!(program.strokes.len(), job.strokes.len());
    assert!(
        summary.drawn_m >= 0.95 * summary.total_m,
        "{name}: drew {} of {} m",
        summary.drawn_m,
        summary.total_m
    );
    // Pen down, lifted between strokes: every stroke part has a retreat after it and an
    // approach before it, or a pen-up move blended from one part to the next (lift, move and
    // set-down: three vertices or more) between them; the pencil's two strokes are joined so.
    let kinds: Vec<SegmentKind> = program.segments.iter().map(|s| s.kind).collect();
    let blended = |k: usize| {
        program.segments[k].kind == SegmentKind::Travel && program.segments[k].vertices.len() >= 3
    };
    for (k, kind) in kinds.iter().enumerate() {
        if matches!(kind, SegmentKind::Stroke { .. }) {
            assert!(
                kinds[k + 1] == SegmentKind::Retreat || blended(k + 1),
                "{name}: {kinds:?}"
            );
            assert!(
                kinds[k - 1] == SegmentKind::Approach || blended(k - 1),
                "{name}: {kinds:?}"
            );
        }
    }
    assert!(
        (0..kinds.len()).any(blended),
        "{name}: no blended move in {kinds:?}"
    );
    for pair in program.segments.windows(2) {
        assert_eq!(
            pair[0].end_s, pair[1].start_s,
            "segments follow one another"
        );
    }
    let check = verify_job(&program, &checker, planner.robot().joint_names())
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(check.points, program.points().len());
    assert!(check.moves > check.stroke_parts);
    // A program moved off its stroke is refused.
    let mut moved = program.clone();
    let stroke = moved
        .segments
        .iter()
        .position(|s| matches!(s.kind, SegmentKind::Stroke { .. }))
        .expect("a stroke segment");
    let task = moved.segments[stroke].task.as_mut().expect("its task");
    task.p0.x += 0.01;
    if let Some(path) = &task.path {
        let mut spec = path.spec().clone();
        spec.start[0] += 0.01;
        for segment in &mut spec.segments {
            if let emg_control::SegmentSpec::Line { to } = segment {
                to[0] += 0.01;
            }
            if let emg_control::SegmentSpec::Arc {
                centre: Some(c), ..
            } = segment
            {
                c[0] += 0.01;
            }
        }
        task.path = Some(emg_control::Path::new(spec).expect("the moved stroke"));
    }
    let failure = verify_job(&moved, &checker, planner.robot().joint_names()).unwrap_err();
    assert!(failure.to_string().contains("off the line"), "{failure}");
}

#[test]
fn an_icon_is_planned_and_checked_on_the_fr3() {
    plans_and_checks_the_pencil_icon("fr3");
}

#[test]
fn an_icon_is_planned_and_checked_on_the_ur5e() {
    plans_and_checks_the_pencil_icon("ur5e");
}

#[test]
fn wrong_jobs_are_refused_naming_what_is_wrong() {
    let (planner, timing, _, file) = common::setup("fr3");
    let robot = planner.robot();
    let parse = |text: &str| {
        Job::from_json("job.json", text, robot)
            .map(|_| ())
            .unwrap_err()
    };
    assert!(matches!(
        parse(r#"{"version": 1, "strokes": []}"#),
        JobError::NoStrokes
    ));
    let off_plane = parse(
        r#"{"version": 1, "strokes": [{"version": 1, "start": [0.45, 0, 0.25], "normal": [0, 0, -1],
            "segments": [{"line": {"to": [0.5, 0, 0.3]}}]}]}"#,
    );
    assert!(
        off_plane
            .to_string()
            .starts_with("job field 'strokes[0]': path field 'segments[0].line.to' lies"),
        "{off_plane}"
    );
    assert!(matches!(
        parse(r#"{"version": 2, "strokes": []}"#),
        JobError::Version { found: 2 }
    ));
    let home = parse(
        r#"{"version": 1, "home": [0, 0, 0], "strokes": [{"version": 1, "start": [0.45, 0, 0.25],
            "normal": [0, 0, -1], "segments": [{"line": {"to": [0.45, 0.1, 0.25]}}]}]}"#,
    );
    assert!(home.to_string().contains("has 3 values"), "{home}");
    let lift = parse(
        r#"{"version": 1, "settings": {"lift_m": -1}, "strokes": [{"version": 1, "start": [0.45, 0, 0.25],
            "normal": [0, 0, -1], "segments": [{"line": {"to": [0.45, 0.1, 0.25]}}]}]}"#,
    );
    assert!(lift.to_string().contains("settings.lift_m"), "{lift}");
    // A drawing placed where the arm cannot reach any of it.
    let far = Placement {
        origin_m: [3.0, 0.0, 0.25],
        ..Placement::default()
    };
    let job = icon_job(robot, "heart", &far);
    let failure = plan_job(
        &planner,
        &PlanRequest::default(),
        &job,
        &timing,
        &file.display().to_string(),
        &emg_job::Unwatched,
    )
    .unwrap_err();
    assert!(
        failure
            .to_string()
            .starts_with("no stroke of the job can be drawn"),
        "{failure}"
    );
}

/// A watch that counts how often it is asked to stop and asks to from its `stop_from`-th
/// question on (never with `usize::MAX`).
struct Counting {
    asked: std::sync::atomic::AtomicUsize,
    stop_from: usize,
}

impl emg_job::Watch for Counting {
    fn progress(&self, _stage: &str, _done: usize, _total: usize) {}

    fn stop_requested(&self) -> bool {
        let asked = self.asked.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1;
        asked >= self.stop_from
    }
}

#[test]
fn a_stop_is_asked_for_between_a_searchs_rollouts_and_ends_the_job_at_once() {
    let (planner, timing, _, file) = common::setup("fr3");
    // A line running out of the arm's reach: its search spends its whole budget.
    let job = Job::from_json(
        "job.json",
        r#"{"version": 1, "strokes": [{"version": 1, "start": [0.45, 0, 0.25], "normal": [0, 0, -1],
            "segments": [{"line": {"to": [1.2, 0, 0.25]}}]}]}"#,
        planner.robot(),
    )
    .expect("a valid job");
    let plan = |watch: &Counting| {
        plan_job(
            &planner,
            &PlanRequest::default(),
            &job,
            &timing,
            &file.display().to_string(),
            watch,
        )
    };
    let never = Counting {
        asked: 0.into(),
        stop_from: usize::MAX,
    };
    let program = plan(&never).expect("planned");
    // One stroke: asked before its searches and while connecting only a handful of times;
    // every further question came from inside a search.
    let asked = never.asked.into_inner();
    assert!(
        asked > 4 * (program.summary.searches + 2),
        "asked {asked} times in {} searches",
        program.summary.searches
    );
    // Asked to stop in the middle of the first search, the job stops there.
    let midway = Counting {
        asked: 0.into(),
        stop_from: 3,
    };
    assert!(matches!(
        plan(&midway),
        Err(emg_job::JobPlanError::Stopped(_))
    ));
    assert!(midway.asked.into_inner() <= 6);
}

/// The signature 0.4 m wide at `origin_m` on the FR3, planned as `emg job` plans it (checked by
/// the independent checker) with `max_parts`, and with the strokes' directions fixed as the file
/// has them and reversed: the length each draws of every stroke, and the program.
fn signature_each_way(origin_m: [f64; 3], max_parts: usize) -> ([Vec<f64>; 3], emg_job::JobFile) {
    let (planner, timing, checker, file) = common::setup("fr3");
    let robot = planner.robot();
    let placement = Placement {
        origin_m,
        width_m: Some(0.4),
        ..Placement::default()
    };
    let mut job = icon_job(robot, "signature", &placement);
    job.settings.max_parts = max_parts;
    let plan = |job: &Job| {
        let program = common::plan(&planner, &timing, &file, job);
        verify_job(&program, &checker, robot.joint_names()).expect("the checker passes it");
        assert!(
            program
                .ordering
                .drawn
                .iter()
                .all(|chain| chain.0.len() == 1)
        );
        let mut drawn = vec![0.0; job.strokes.len()];
        for report in &program.strokes {
            drawn[report.stroke] = report.drawn_m;
        }
        (drawn, program)
    };
    let mut given = job.clone();
    given.settings.order = emg_job::Order::Given;
    let mut reversed = given.clone();
    reversed.strokes = job
        .strokes
        .iter()
        .map(|path| path.reversed().expect("reversible"))
        .collect();
    let (chosen, program) = plan(&job);
    let ((forward, _), (backward, _)) = (plan(&given), plan(&reversed));
    for k in 0..job.strokes.len() {
        assert!(
            chosen[k] >= forward[k].max(backward[k]) - emg_job::SAME_LENGTH_M,
            "stroke {k}: {} m drawn, {} m forward, {} m backward",
            chosen[k],
            forward[k],
            backward[k]
        );
    }
    ([chosen, forward, backward], program)
}

#[test]
fn each_stroke_is_drawn_the_way_that_draws_more() {
    // Near the edge of the FR3's reach the signature's long stroke drawn from its end draws
    // 1.09 m, from its start 1.17 m (the way the order stage would draw it for a shorter
    // travel is the first).
    let default = emg_job::JobSettings::default().max_parts;
    let ([chosen, forward, backward], program) = signature_each_way([0.6, 0.5, 0.05], default);
    let better: f64 = (0..chosen.len()).map(|k| forward[k].max(backward[k])).sum();
    assert!(
        backward.iter().sum::<f64>() < better - 0.05
            && program.summary.drawn_m >= 0.99 * program.summary.total_m,
        "{forward:?} {backward:?} {chosen:?} {} of {} m",
        program.summary.drawn_m,
        program.summary.total_m
    );
}

#[test]
fn a_part_is_kept_only_where_the_tool_can_lift_off_its_start() {
    // The signature 0.3 m wide 0.78 m out at the plate's height: the long stroke's first motion
    // the searches find starts where the arm, stretched out, cannot lift the tool off the part,
    // so the connect stage could not set it down there (kept, it was left out there and the
    // stroke drew 88.9 % of the job; the searches now go on past it: 96.3 %).
    let (planner, timing, checker, file) = common::setup("fr3");
    let robot = planner.robot();
    let placement = Placement {
        origin_m: [0.78, 0.0, 0.25],
        width_m: Some(0.3),
        ..Placement::default()
    };
    let job = icon_job(robot, "signature", &placement);
    let program = common::plan(&planner, &timing, &file, &job);
    verify_job(&program, &checker, robot.joint_names()).expect("the checker passes it");
    for report in &program.strokes {
        assert!(report.parts_left_out.is_empty(), "{report:?}");
    }
    assert!(
        program.summary.drawn_m >= 0.95 * program.summary.total_m,
        "{} of {} m",
        program.summary.drawn_m,
        program.summary.total_m
    );
}

#[test]
fn a_stroke_left_short_is_finished_from_its_other_end() {
    // Farther out, with one part a stroke, neither way draws the long stroke whole: the part
    // from its other end draws on back toward where the first stopped.
    let ([chosen, forward, backward], program) = signature_each_way([0.3, 0.75, 0.2], 1);
    let from_the_end = program
        .segments
        .iter()
        .filter(|s| matches!(s.kind, SegmentKind::Stroke { backward: true, .. }))
        .count();
    assert!(from_the_end >= 1);
    let (drawn, better) = (
        chosen.iter().sum::<f64>(),
        (0..chosen.len())
            .map(|k| forward[k].max(backward[k]))
            .sum::<f64>(),
    );
    assert!(
        drawn > better + 0.1,
        "{drawn} m drawn, {better} m the better way of each stroke"
    );
}

#[test]
fn a_stroke_longer_than_one_rollout_is_drawn_whole_and_what_is_not_searched_is_said() {
    let (planner, timing, _, file) = common::setup("fr3");
    let robot = planner.robot();
    // 28 turns round a circle 5 cm across (8.8 m): more than one rollout draws (5 m at its
    // step cap), with one counted search; parts that stop only at the step cap are not counted.
    let turn = r#"{"arc": {"centre": [0.45, 0, 0.25], "sweep_deg": 360}}"#;
    let coil = format!(
        r#"{{"version": 1, "settings": {{"max_parts": 1}}, "strokes": [{{"version": 1,
            "start": [0.5, 0, 0.25], "normal": [0, 0, -1], "segments": [{}]}}]}}"#,
        vec![turn; 28].join(", ")
    );
    let job = Job::from_json("coil.json", &coil, robot).expect("a valid job");
    let program = common::plan(&planner, &timing, &file, &job);
    let report = &program.strokes[0];
    assert!(report.parts >= 2, "{} parts", report.parts);
    assert!(report.drawn_m >= report.length_m - 1e-3, "{report:?}");
    assert_eq!(report.unsearched_from_s, None);
    // A line out of reach and back twice, one part each way: what lies between the part
    // from its start and the part from its end was not searched, and the program says so.
    let zigzag = format!(
        r#"{{"version": 1, "settings": {{"max_parts": 1}}, "strokes": [{}]}}"#,
        OUT_AND_BACK_TWICE
    );
    let job = Job::from_json("zigzag.json", &zigzag, robot).expect("a valid job");
    let program = common::plan(&planner, &timing, &file, &job);
    let report = &program.strokes[0];
    let unsearched = report.unsearched_from_s.expect("the search was spent");
    assert!(
        report.parts == 2 && report.unreached.len() == 1,
        "{report:?}"
    );
    let gap = report.unreached[0];
    assert!(
        (unsearched - gap.from_s).abs() < 0.01 && gap.to_s < report.length_m - 0.1,
        "{unsearched} {gap:?}"
    );
}

/// A stroke of straight legs out to 1 m in front of the FR3 at the plate's height (beyond its
/// reach) and back, twice.
const OUT_AND_BACK_TWICE: &str = r#"{"version": 1, "start": [0.45, 0, 0.25],
    "normal": [0, 0, -1], "segments": [{"line": {"to": [1.0, 0, 0.25]}},
    {"line": {"to": [0.45, 0.06, 0.25]}}, {"line": {"to": [1.0, 0.12, 0.25]}},
    {"line": {"to": [0.45, 0.18, 0.25]}}]}"#;

#[test]
fn a_stroke_leaving_the_reach_twice_is_searched_past_both_gaps() {
    // A zigzag whose two far vertices lie 1 m out, beyond the FR3's reach at this height: the
    // stretch between the gaps (the near vertex and most of the two legs it joins, 0.75 m)
    // is searched only where the searches that gain nothing skip further and further ahead
    // (with a fixed 5 mm skip they were spent 3 cm into the first gap: 42.7 % drawn).
    let (planner, timing, checker, file) = common::setup("fr3");
    let robot = planner.robot();
    let zigzag = format!(r#"{{"version": 1, "strokes": [{OUT_AND_BACK_TWICE}]}}"#);
    let job = Job::from_json("zigzag.json", &zigzag, robot).expect("a valid job");
    let program = common::plan(&planner, &timing, &file, &job);
    verify_job(&program, &checker, robot.joint_names()).expect("the checker passes it");
    let report = &program.strokes[0];
    assert_eq!(report.unsearched_from_s, None, "{report:?}");
    // The near vertex between the gaps is drawn: no stretch left undrawn covers it.
    let leg = |a: [f64; 2], b: [f64; 2]| ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
    let near_vertex_s = leg([0.45, 0.0], [1.0, 0.0]) + leg([1.0, 0.0], [0.45, 0.06]);
    assert!(
        report
            .unreached
            .iter()
            .all(|u| !(u.from_s..=u.to_s).contains(&near_vertex_s)),
        "{:?}",
        report.unreached
    );
    assert!(
        report.drawn_m >= 0.7 * report.length_m,
        "{} of {} m",
        report.drawn_m,
        report.length_m
    );
}

#[test]
fn a_closed_stroke_starting_out_of_reach_is_started_where_the_arm_reaches_it() {
    // A circle 0.2 m across, 0.9 m out at the height of the plate, starting at its far side,
    // 1 m out: no part starts there; the searches skip round it to its near side, where one
    // part draws most of it.
    let (planner, timing, checker, file) = common::setup("fr3");
    let robot = planner.robot();
    let circle = r#"{"version": 1, "strokes": [{"version": 1, "start": [1.0, 0, 0.05],
        "normal": [0, 0, -1], "segments": [{"arc": {"centre": [0.9, 0, 0.05], "sweep_deg": 360}}]}]}"#;
    let job = Job::from_json("circle.json", circle, robot).expect("a valid job");
    let program = common::plan(&planner, &timing, &file, &job);
    verify_job(&program, &checker, robot.joint_names()).expect("the checker passes it");
    let report = &program.strokes[0];
    assert!(
        report.drawn_m >= 0.5 * report.length_m,
        "{} of {} m",
        report.drawn_m,
        report.length_m
    );
    assert_eq!(report.parts, 1, "{report:?}");
}

/// A watch that records every progress it is told.
#[derive(Default)]
struct Recording(std::sync::Mutex<Vec<(String, usize, usize)>>);

impl emg_job::Watch for Recording {
    fn progress(&self, stage: &str, done: usize, total: usize) {
        self.0
            .lock()
            .expect("not poisoned")
            .push((stage.to_string(), done, total));
    }
}

#[test]
fn planning_a_long_stroke_shows_its_progress_in_millimetres() {
    let (planner, timing, _, file) = common::setup("fr3");
    // 28 turns round a circle 5 cm across: 8.8 m, one stroke of several searches.
    let turn = r#"{"arc": {"centre": [0.45, 0, 0.25], "sweep_deg": 360}}"#;
    let coil = format!(
        r#"{{"version": 1, "strokes": [{{"version": 1, "start": [0.5, 0, 0.25],
            "normal": [0, 0, -1], "segments": [{}]}}]}}"#,
        vec![turn; 28].join(", ")
    );
    let job = Job::from_json("coil.json", &coil, planner.robot()).expect("a valid job");
    let watch = Recording::default();
    plan_job(
        &planner,
        &emg_planner::PlanRequest::default(),
        &job,
        &timing,
        &file.display().to_string(),
        &watch,
    )
    .expect("planned");
    let planning: Vec<(usize, usize)> = watch
        .0
        .into_inner()
        .expect("not poisoned")
        .into_iter()
        .filter(|(stage, _, _)| stage == "planning")
        .map(|(_, done, total)| (done, total))
        .collect();
    let total = (job.strokes[0].length_m() * 1e3).round() as usize;
    assert!(planning.len() >= 3, "{planning:?}");
    assert!(planning.iter().all(|&(_, t)| t == total));
    assert!(planning.windows(2).all(|w| w[0].0 < w[1].0), "{planning:?}");
    assert_eq!(planning.first().map(|p| p.0), Some(0));
    assert_eq!(planning.last().map(|p| p.0), Some(total));
}
