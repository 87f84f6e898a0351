//! A small job's program built without the job planner (this crate does not depend on it): two
//! strokes on the FR3's mid-range tool plane, a line drawn whole and a half circle drawn in two
//! parts with a stretch between them not drawn, joined by joint-space moves, on one time line.

use std::ops::Range;

use emg_control::{
    ClassicalController, ConstraintConfig, Path, PathSpec, RolloutConfig, SegmentSpec, Task,
    Trajectory, rollout,
};
use emg_kinematics::{JointVector, Robot, Vec3, WorkSurface};
use emg_viewer::{
    JobSample, JobSegment, JobSegmentKind, JobViewerInput, drawn_stretches, render_job_html,
};

/// The shipped FR3 robot file.
pub fn fr3_path() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fr3_pen.urdf")
}

/// One segment of the program: its kind, span and (a stroke part's) task's index.
#[derive(Clone, Debug)]
pub struct Span {
    /// What it does.
    pub kind: JobSegmentKind,
    /// Start and end (s).
    pub start_s: f64,
    /// See `start_s`.
    pub end_s: f64,
    /// Into [`SyntheticJob::tasks`].
    pub task: Option<usize>,
}

/// The program and what it is made of.
pub struct SyntheticJob {
    /// The FR3.
    pub robot: Robot,
    /// Stroke 0 (a line, 12 cm) and stroke 1 (a half circle of radius 5 cm from stroke 0's end).
    pub strokes: Vec<Path>,
    /// The stroke parts' tasks, in program order.
    pub tasks: Vec<Task>,
    /// The segments in time order.
    pub spans: Vec<Span>,
    /// The samples (moves at 1 kHz; stroke parts at the rollout's steps).
    pub samples: Vec<JobSample>,
    /// The work plate on, no obstacles.
    pub constraints: ConstraintConfig,
    /// Stroke 1's stretch between its parts: from the farthest its first part reaches to where
    /// its second part's task starts (arc length, m).
    pub gap: Range<f64>,
}

/// The segments and samples so far.
#[derive(Default)]
struct Builder {
    samples: Vec<JobSample>,
    spans: Vec<Span>,
}

impl Builder {
    /// Appends `motion` ((time from its start, configuration), from the program's last
    /// configuration) as a segment of `kind`.
    fn append(&mut self, kind: JobSegmentKind, motion: &[(f64, JointVector)], task: Option<usize>) {
        let offset = self.samples.last().map_or(0.0, |s| s.time_s);
        let skip = usize::from(!self.samples.is_empty());
        self.samples
            .extend(motion.iter().skip(skip).map(|(t, q)| JobSample {
                time_s: offset + t,
                q: *q,
            }));
        self.spans.push(Span {
            kind,
            start_s: offset,
            end_s: self.samples.last().expect("a sample").time_s,
            task,
        });
    }

    /// A straight joint-space move through `vertices`, 0.3 s an edge, sampled at 1 kHz.
    fn append_move(&mut self, kind: JobSegmentKind, vertices: &[JointVector]) {
        let mut motion = vec![(0.0, vertices[0])];
        for (edge, pair) in vertices.windows(2).enumerate() {
            for k in 1..=300 {
                let f = k as f64 / 300.0;
                motion.push((
                    (edge * 300 + k) as f64 * 1e-3,
                    pair[0] + (pair[1] - pair[0]) * f,
                ));
            }
        }
        self.append(kind, &motion, None);
    }

    /// The rollout's steps `range` as a stroke part, its times from its first.
    fn append_part(
        &mut self,
        kind: JobSegmentKind,
        trajectory: &Trajectory,
        range: Range<usize>,
        task: usize,
    ) {
        let steps = &trajectory.steps[range];
        let t0 = steps[0].time_s;
        let motion: Vec<_> = steps.iter().map(|s| (s.time_s - t0, s.q)).collect();
        self.append(kind, &motion, Some(task));
    }
}

/// `q` with joint 3 (the elbow) turned by `angle`: the tool lifted off the surface.
fn lifted(q: &JointVector, angle: f64) -> JointVector {
    let mut q = *q;
    q[3] += angle;
    q
}

/// Plans the program's stroke parts with the classical controller and joins them.
pub fn synthetic_job() -> SyntheticJob {
    let robot =
        Robot::from_urdf_file(fr3_path(), "link0", "pen_tip").expect("the FR3 robot file loads");
    let config = RolloutConfig::default();
    let plan = |task: &Task, seed: &JointVector| {
        rollout(
            &robot,
            task,
            seed,
            &mut ClassicalController::default(),
            &config,
        )
    };
    let seed = robot.mid_range();
    let kin = robot.forward(&seed);
    let (p, n) = (kin.tcp(), kin.tool_axis());
    let d = (Vec3::y() - n * Vec3::y().dot(&n)).normalize();
    let line = Path::straight(p, d, n, 0.12).expect("a valid line");
    let line_task = Task::on_path(&robot, line.clone(), None).expect("a valid line task");
    let drawn_line = plan(&line_task, &seed);
    assert_eq!(
        drawn_line.termination,
        emg_control::Termination::Completed,
        "stroke 0 is drawn whole"
    );
    let end_q = drawn_line.steps.last().expect("a step").q;
    let start = robot.forward(&end_q).tcp();
    let across = n.cross(&d);
    let arc = Path::new(PathSpec {
        version: 1,
        start: start.into(),
        normal: n.into(),
        blend_radius_m: 0.0,
        segments: vec![SegmentSpec::Arc {
            centre: Some((start + across * 0.05).into()),
            through: None,
            to: None,
            sweep_deg: Some(180.0),
        }],
    })
    .expect("a valid half circle");
    let arc_task = Task::on_path(&robot, arc.clone(), None).expect("a valid arc task");
    let drawn_arc = plan(&arc_task, &end_q);
    assert_eq!(
        drawn_arc.termination,
        emg_control::Termination::Completed,
        "the half circle is followed whole"
    );
    // Its first part stops at 40 % of the arc; its second starts at 60 %, on the stretch from
    // there to the end.
    let length = arc.length_m();
    let arc_s: Vec<f64> = {
        let mut hint = 0.0;
        drawn_arc
            .steps
            .iter()
            .map(|s| {
                hint = arc_task.along(&robot.forward(&s.q).tcp(), hint).s_m;
                hint
            })
            .collect()
    };
    let stop = arc_s
        .iter()
        .rposition(|s| *s <= 0.4 * length)
        .expect("a step");
    let resume = arc_s
        .iter()
        .position(|s| *s >= 0.6 * length)
        .expect("a step");
    let resume_s = arc_s[resume];
    let rest = arc.stretch(resume_s, length).expect("a stretch");
    let rest_task = Task::on_path(&robot, rest, None).expect("a valid stretch task");

    let mut program = Builder::default();
    let stroke = |stroke, part| JobSegmentKind::Stroke { stroke, part };
    let first = drawn_line.steps[0].q;
    program.append_move(JobSegmentKind::Approach, &[lifted(&first, 0.15), first]);
    program.append_part(stroke(0, 0), &drawn_line, 0..drawn_line.steps.len(), 0);
    program.append_move(JobSegmentKind::Retreat, &[end_q, lifted(&end_q, 0.15)]);
    let detour = lifted(&end_q, 0.15) + JointVector::from([0.4, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    program.append_move(
        JobSegmentKind::Travel,
        &[lifted(&end_q, 0.15), detour, lifted(&end_q, 0.15)],
    );
    program.append_move(JobSegmentKind::Approach, &[lifted(&end_q, 0.15), end_q]);
    program.append_part(stroke(1, 0), &drawn_arc, 0..stop + 1, 1);
    let (stopped, resumed) = (drawn_arc.steps[stop].q, drawn_arc.steps[resume].q);
    program.append_move(JobSegmentKind::Retreat, &[stopped, lifted(&stopped, 0.15)]);
    program.append_move(
        JobSegmentKind::Travel,
        &[lifted(&stopped, 0.15), lifted(&resumed, 0.15)],
    );
    program.append_move(JobSegmentKind::Approach, &[lifted(&resumed, 0.15), resumed]);
    program.append_part(stroke(1, 1), &drawn_arc, resume..drawn_arc.steps.len(), 2);
    let last = drawn_arc.steps.last().expect("a step").q;
    program.append_move(JobSegmentKind::Retreat, &[last, lifted(&last, 0.15)]);

    let mut constraints = config.constraints.clone();
    constraints.work_surface = WorkSurface::plate();
    SyntheticJob {
        robot,
        strokes: vec![line, arc],
        tasks: vec![line_task, arc_task, rest_task],
        spans: program.spans,
        samples: program.samples,
        constraints,
        gap: arc_s[stop]..resume_s,
    }
}

impl SyntheticJob {
    /// The segments as the viewer takes them.
    pub fn segments(&self) -> Vec<JobSegment<'_>> {
        self.spans
            .iter()
            .map(|span| JobSegment {
                kind: span.kind,
                start_s: span.start_s,
                end_s: span.end_s,
                task: span.task.map(|index| &self.tasks[index]),
            })
            .collect()
    }

    /// The stretches the program draws ([`drawn_stretches`]).
    pub fn reached(&self) -> Vec<Vec<Range<f64>>> {
        drawn_stretches(&self.robot, &self.strokes, &self.segments(), &self.samples)
    }

    /// The job page, its plate drawn under stroke 0's task.
    pub fn page(&self, title: &str) -> String {
        let segments = self.segments();
        let reached = self.reached();
        render_job_html(&JobViewerInput {
            robot: &self.robot,
            strokes: &self.strokes,
            reached: &reached,
            segments: &segments,
            samples: &self.samples,
            surfaces: std::slice::from_ref(&self.tasks[0]),
            constraints: &self.constraints,
            title,
        })
    }
}
