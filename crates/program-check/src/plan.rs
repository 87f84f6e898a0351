//! The plan's side of a reading: its stroke parts as the checker reads them, and what the arm
//! has drawn so far checked against them.

use emg_control::{ConstraintConfig, task_bounds};
use emg_job::{Coverage, JobFile, SegmentKind, Stretch, with_part};
use emg_kinematics::Vec3;
use emg_verify::{Bounds, Joints, Line, ReferenceModel};

/// Coverage the tool may fall short of the plan's claims, per stroke part (m).
pub const COVERAGE_ALLOWANCE_M: f64 = 1e-3;
/// Rounding slack of the tolerance checks (m).
const SLACK_M: f64 = 1e-9;
/// Rounding slack of the cone checks (degrees).
const SLACK_DEG: f64 = 1e-6;

/// A stroke part of the plan as a reader checks it.
struct StrokePart {
    /// Its segment's index.
    segment: usize,
    /// Its stroke's place in the file's `strokes`.
    place: usize,
    /// Arc length along the stroke where its task starts (m).
    from_s: f64,
    /// Whether its task runs from `from_s` back toward the stroke's start.
    backward: bool,
    /// Its task as the checker reads it.
    line: Line,
    /// The bounds its samples keep (the part in the scene).
    bounds: Bounds,
    /// The TCP at its first and last sample.
    start: Vec3,
    /// See `start`.
    end: Vec3,
}

/// The plan's side of a reading: its stroke parts, the checker and the bounds moves keep.
pub struct PlanChecks<'a> {
    model: &'a ReferenceModel,
    limits: Vec<(f64, f64)>,
    collision_margin_m: f64,
    /// The line and bounds of the moves between strokes (the part in the scene), if the plan
    /// has a part.
    free: Option<(Line, Bounds)>,
    parts: Vec<StrokePart>,
}

/// What the arm has done so far, as the program runs: the tool, the stroke part being drawn,
/// the stretches covered, and the worst figures met.
#[derive(Clone, Debug, Default)]
pub struct Drawing {
    /// Whether the tool is on.
    pub tool_on: bool,
    /// Stroke parts switched on so far.
    pub parts_on: usize,
    /// The TCP samples of the stroke part being drawn.
    drawn: Vec<Vec3>,
    /// How far along its task the last of them stands (m, [`Line::follow`]).
    progress_m: f64,
    /// Per stroke (its place), the stretches covered.
    covered: Vec<Vec<Stretch>>,
    /// Configurations checked.
    pub samples: usize,
    /// Largest distance (m) of the TCP from its task while the tool is on.
    pub worst_deviation_m: f64,
    /// Largest angle (degrees) of the tool axis from its task's normal while the tool is on.
    pub worst_tool_angle_deg: f64,
    /// Smallest self-clearance (m) met.
    pub least_clearance_m: f64,
}

/// The coverage a finished reading found.
#[derive(Clone, Debug, PartialEq)]
pub struct Covered {
    /// Per stroke, the length of its path covered while the tool was on and the length the
    /// plan says is drawn (m).
    pub per_stroke: Vec<(f64, f64)>,
    /// Total covered while the tool was on (m).
    pub covered_m: f64,
    /// Total the plan draws (m).
    pub drawn_m: f64,
}

/// The checker's joint vector of a six-joint configuration.
pub fn checker_joints(q: &[f64; 6]) -> Joints {
    let mut joints = Joints::zeros();
    for (i, value) in q.iter().enumerate() {
        joints[i] = *value;
    }
    joints
}

impl<'a> PlanChecks<'a> {
    /// The plan `file`'s side of a reading with the checker `model` of its six-joint arm.
    pub fn new(file: &JobFile, model: &'a ReferenceModel) -> Result<Self, String> {
        if file.joint_names.len() != 6 || model.limits().len() != 6 {
            return Err("the plan is not a six-joint arm's".to_string());
        }
        let points = file.points();
        let times: Vec<f64> = points.iter().map(|p| p.time_from_start.seconds()).collect();
        let tcp = |k: usize| {
            let q: [f64; 6] = std::array::from_fn(|i| points[k].positions[i]);
            model.tcp_frame(&checker_joints(&q)).0
        };
        let on_part = with_part(&file.constraints, &file.surfaces);
        let free_config = ConstraintConfig {
            line_tolerance_m: f64::INFINITY,
            theta_max_deg: 180.0,
            ..on_part.clone()
        };
        let free = file
            .surfaces
            .first()
            .map(|task| (task.into(), task_bounds(task, &free_config)));
        let mut parts = Vec::new();
        for (segment, s) in file.segments.iter().enumerate() {
            let SegmentKind::Stroke {
                stroke,
                from_s,
                backward,
                ..
            } = s.kind
            else {
                continue;
            };
            let task = s.task.as_ref().ok_or_else(|| {
                format!("the plan's segment {segment} is a stroke without its task")
            })?;
            let place = file
                .strokes
                .iter()
                .position(|r| r.stroke == stroke)
                .ok_or_else(|| format!("the plan's stroke {stroke} has no report"))?;
            let first = times.partition_point(|t| *t < s.start_s - 1e-9);
            let last = times.partition_point(|t| *t <= s.end_s + 1e-9);
            if first >= last {
                return Err(format!("the plan's segment {segment} holds no sample"));
            }
            parts.push(StrokePart {
                segment,
                place,
                from_s,
                backward,
                line: task.into(),
                bounds: task_bounds(task, &on_part),
                start: tcp(first),
                end: tcp(last - 1),
            });
        }
        Ok(Self {
            model,
            limits: model.limits(),
            collision_margin_m: file.constraints.collision_margin_m,
            free,
            parts,
        })
    }

    /// The joint limits (rad), base to tip.
    pub fn limits(&self) -> &[(f64, f64)] {
        &self.limits
    }

    /// A reading's start: nothing drawn, for a plan of `strokes` strokes.
    pub fn start(&self, strokes: usize) -> Drawing {
        Drawing {
            covered: vec![Vec::new(); strokes],
            least_clearance_m: f64::INFINITY,
            ..Drawing::default()
        }
    }

    /// Checks a configuration the arm passes: the joint limits and the checker's clearances
    /// (its own links; the part and the scene by the bounds of the stroke part being drawn, or
    /// of the moves between strokes).
    pub fn configuration(&self, drawing: &mut Drawing, q: &[f64; 6]) -> Result<(), String> {
        drawing.samples += 1;
        for (i, (value, (low, high))) in q.iter().zip(&self.limits).enumerate() {
            if !(value >= low && value <= high) {
                return Err(format!(
                    "joint {} = {value} leaves its limits [{low}, {high}]",
                    i + 1
                ));
            }
        }
        let joints = checker_joints(q);
        let (clearance, a, b) = self.model.min_clearance(&joints);
        drawing.least_clearance_m = drawing.least_clearance_m.min(clearance);
        if clearance < self.collision_margin_m - SLACK_M {
            return Err(format!(
                "{a} and {b} come within {:.2} mm at {q:?}",
                clearance * 1e3
            ));
        }
        let scene = if drawing.tool_on {
            let part = &self.parts[drawing.parts_on - 1];
            Some((&part.line, &part.bounds))
        } else {
            self.free.as_ref().map(|(line, bounds)| (line, bounds))
        };
        if let Some((task, bounds)) = scene
            && let Some((margin, link, obstacle)) = self.model.scene_margin(&joints, task, bounds)
            && margin < -SLACK_M
        {
            return Err(format!(
                "{link} comes {:.2} mm into {obstacle} at {q:?}",
                -margin * 1e3
            ));
        }
        Ok(())
    }

    /// Checks the TCP at `position` with the tool axis `axis` while the tool is on: within the
    /// tolerance of the stroke part's task, measured from the stretch of it reached, and the
    /// axis within the cone round its normal.
    pub fn on_task(
        &self,
        drawing: &mut Drawing,
        position: &Vec3,
        axis: &Vec3,
    ) -> Result<(), String> {
        let part = &self.parts[drawing.parts_on - 1];
        let (progress_m, deviation) = part.line.follow(position, drawing.progress_m);
        drawing.progress_m = progress_m;
        let angle = angle_deg(axis, &part.line.n);
        drawing.worst_deviation_m = drawing.worst_deviation_m.max(deviation);
        drawing.worst_tool_angle_deg = drawing.worst_tool_angle_deg.max(angle);
        if deviation > part.bounds.line_tolerance_m + SLACK_M {
            return Err(format!(
                "the TCP {:?} lies {:.4} mm from stroke part {} (segment {}), {:.4} m along \
                 it; the tolerance is {:.4} mm",
                position.as_slice(),
                deviation * 1e3,
                drawing.parts_on - 1,
                part.segment,
                progress_m,
                part.bounds.line_tolerance_m * 1e3
            ));
        }
        if angle > part.bounds.theta_max_deg + SLACK_DEG {
            return Err(format!(
                "the tool axis leans {angle:.3}° from the normal of stroke part {}; the cone is \
                 {}°",
                drawing.parts_on - 1,
                part.bounds.theta_max_deg
            ));
        }
        drawing.drawn.push(*position);
        Ok(())
    }

    /// The tool switched on with the TCP at `position`, the tool axis `axis`: the plan's next
    /// stroke part starts there (within its tolerance).
    pub fn switch_on(
        &self,
        drawing: &mut Drawing,
        position: &Vec3,
        axis: &Vec3,
    ) -> Result<(), String> {
        let index = drawing.parts_on;
        let Some(part) = self.parts.get(index) else {
            return Err(format!(
                "the tool switches on a {}th time; the plan draws {} stroke parts",
                index + 1,
                self.parts.len()
            ));
        };
        let off = (position - part.start).norm();
        if off > part.bounds.line_tolerance_m + SLACK_M {
            return Err(format!(
                "the tool switches on {:.4} mm from the start of stroke part {index} (segment {})",
                off * 1e3,
                part.segment
            ));
        }
        drawing.tool_on = true;
        drawing.parts_on += 1;
        drawing.drawn.clear();
        drawing.progress_m = 0.0;
        self.on_task(drawing, position, axis)
    }

    /// The tool switched off with the TCP at `position`: the stroke part ends there (within its
    /// tolerance); what it covered is measured.
    pub fn switch_off(&self, drawing: &mut Drawing, position: &Vec3) -> Result<(), String> {
        let index = drawing.parts_on - 1;
        let part = &self.parts[index];
        let off = (position - part.end).norm();
        if off > part.bounds.line_tolerance_m + SLACK_M {
            return Err(format!(
                "the tool switches off {:.4} mm from the end of stroke part {index} (segment {})",
                off * 1e3,
                part.segment
            ));
        }
        drawing.tool_on = false;
        if let Some((least, greatest)) = part.line.covered(drawing.drawn.drain(..)) {
            // Along the stroke, the task runs on from `from_s`, or back toward its start.
            drawing.covered[part.place].push(if part.backward {
                Stretch {
                    from_s: part.from_s - greatest,
                    to_s: part.from_s - least,
                }
            } else {
                Stretch {
                    from_s: part.from_s + least,
                    to_s: part.from_s + greatest,
                }
            });
        }
        Ok(())
    }

    /// The reading's end: the tool off and every stroke part drawn.
    pub fn finish(&self, drawing: &Drawing) -> Result<(), String> {
        if drawing.tool_on {
            return Err("the program ends with the tool on".to_string());
        }
        if drawing.parts_on != self.parts.len() {
            return Err(format!(
                "the tool switches on {} times; the plan draws {} stroke parts",
                drawing.parts_on,
                self.parts.len()
            ));
        }
        Ok(())
    }

    /// What the tool covered of each stroke of the plan `file` and what the plan draws; refused
    /// where the strokes are covered less far than the plan draws them (by more than
    /// [`COVERAGE_ALLOWANCE_M`] per stroke part).
    pub fn covered(&self, drawing: &Drawing, file: &JobFile) -> Result<Covered, String> {
        let mut covered = Covered {
            per_stroke: Vec::new(),
            covered_m: 0.0,
            drawn_m: 0.0,
        };
        for (stroke, stretches) in file.strokes.iter().zip(&drawing.covered) {
            let coverage = Coverage::of(stroke.length_m, stretches);
            covered.per_stroke.push((coverage.drawn_m, stroke.drawn_m));
            covered.covered_m += coverage.drawn_m;
            covered.drawn_m += stroke.drawn_m;
        }
        let allowance = COVERAGE_ALLOWANCE_M * self.parts.len() as f64;
        if covered.covered_m < covered.drawn_m - allowance {
            return Err(format!(
                "the tool covers {:.6} m of the strokes; the plan draws {:.6} m",
                covered.covered_m, covered.drawn_m
            ));
        }
        Ok(covered)
    }
}

/// The angle (degrees) between two vectors.
fn angle_deg(a: &Vec3, b: &Vec3) -> f64 {
    libm::atan2(a.cross(b).norm(), a.dot(b)).to_degrees()
}
