//! One part at a time: a stroke part timed, lifted at both ends and joined to the program by
//! a free pen-up move that keeps clear of the part, or planned again from where the arm is.

use emg_kinematics::{JointVector, Vec3};
use emg_planner::{MotionTiming, PlanRequest, Planner};
use emg_timing::time_blended_move;

use crate::free_space::{FreeSpace, PEN_UP_CLEARANCE_SHARE};
use crate::program::{Program, SegmentKind};
use crate::shortfall::Shortfall;
use crate::spec::JobSettings;
use crate::stroke::StrokePart;

/// How far before a pen-up move's corner its rounding starts: this share of the shorter of the
/// corner's edges (the tool has risen 60 % of its lift before it moves aside, clear of the
/// [`PEN_UP_CLEARANCE_SHARE`] it keeps off the lift and the set-down).
pub const BLEND_SHARE: f64 = 0.4;

/// How far before a hop's top its rounding starts: this share of the shorter of its two edges
/// (the hop leaves and meets the part along them, [`LIFT_CONE_RUN`]).
pub const HOP_BLEND_SHARE: f64 = 0.5;

/// How high a pen-up hop between close parts rises for each metre of lateral distance: half,
/// so that the tool leaves and meets the surface at about 45°.
pub const HOP_RISE: f64 = 0.5;

/// A hop rises at most this many lifts; parts further apart are joined by the lift, the move
/// and the set-down.
pub const MAX_HOP_RISE_LIFTS: f64 = 4.0;

/// Halvings at most of a pen-up move's straight edge that sags toward the part
/// (`Connector::held_up`): up to 8 edges, each held at the lift at its ends.
pub const MAX_HELD_UP_DEPTH: usize = 3;

/// How much further (m) the tool rises where no straight free move joins two parts at its lift:
/// a torch's lift, clear of what lies on the part.
pub const CLEARANCE_LIFT_M: f64 = 0.03;

/// A stroke part made ready to join the program: timed, with its free configurations above
/// its start and end and the free move to the first from where the arm was.
pub(super) struct Placed {
    pub(super) timed: emg_timing::TimedMotion,
    pub(super) above_start: JointVector,
    pub(super) above_end: JointVector,
    /// Empty when the program begins here.
    pub(super) travel: Vec<JointVector>,
    /// Whether the sampling planner found a stretch of `travel` (else its edges are straight).
    pub(super) sampled: bool,
}

/// The connect stage for one part at a time.
pub(crate) struct Connector<'a> {
    /// The space the arm moves in, the part among its obstacles.
    pub free: &'a FreeSpace<'a>,
    /// How the program is timed.
    pub timing: &'a MotionTiming,
    /// The job's settings.
    pub settings: &'a JobSettings,
}

impl Connector<'_> {
    /// `part` timed and joined to the arm's configuration `from` (none at the program's start;
    /// with the way the tool rose there off the last part, if it did): lifted at both ends,
    /// the free move to above its start; or why it cannot be.
    pub(super) fn place(
        &self,
        part: &StrokePart,
        from: Option<(JointVector, Option<Vec3>)>,
        seed: u64,
    ) -> Result<(StrokePart, Placed), Shortfall> {
        let robot = self.free.robot();
        let timed = self
            .timing
            .time(robot, &part.task, self.free.constraints(), &part.trajectory)
            .map_err(|e| Shortfall::Untimed { why: e.to_string() })?;
        let start = timed.samples[0].q;
        let end = timed.samples[timed.samples.len() - 1].q;
        // The tool lifts the job's height where that is free, else half or a quarter of it.
        let above = |q: &JointVector, what: &str| {
            self.free
                .lifted(q, &-part.task.n, self.settings.lift())
                .ok_or_else(|| Shortfall::LeftOut {
                    why: FreeSpace::cannot_lift(self.settings.lift(), what),
                })
        };
        let above_start = above(&start, "start")?;
        let above_end = above(&end, "end")?;
        let (travel, sampled) = match from {
            None => (Vec::new(), false),
            Some((from, risen)) => self
                .travel(&from, risen, &above_start, &-part.task.n, seed)
                .ok_or_else(|| Shortfall::LeftOut {
                    why: format!(
                        "no free move to its start found in {} samples",
                        self.settings.rrt_max_samples
                    ),
                })?,
        };
        Ok((
            part.clone(),
            Placed {
                timed,
                above_start,
                above_end,
                travel,
                sampled,
            },
        ))
    }

    /// The free move from `from` (risen along `risen` off the last part, if it did) to `to`
    /// (above the next part, which the tool leaves along `up`): the straight joint-space edge
    /// where it is free; else over both, each risen [`CLEARANCE_LIFT_M`] further where that is
    /// free, the straight edge between them or a sampled move ([`FreeSpace::connect`]); else a
    /// sampled move between `from` and `to` themselves. With whether the sampling planner found
    /// a stretch of it.
    fn travel(
        &self,
        from: &JointVector,
        risen: Option<Vec3>,
        to: &JointVector,
        up: &Vec3,
        seed: u64,
    ) -> Option<(Vec<JointVector>, bool)> {
        let clear = |path: &[JointVector]| self.free.move_free(path, self.pen_up_clearance_m());
        if let Some(path) = self.held_up(from, to, up, MAX_HELD_UP_DEPTH)
            && clear(&path)
        {
            return Some((path, false));
        }
        let robot = self.free.robot();
        let rise = |q: &JointVector, up: &Vec3| {
            self.free
                .reach_point(q, &(robot.forward(q).tcp() + up * CLEARANCE_LIFT_M))
        };
        let over = || {
            let (high_from, high_to) = (
                risen.map_or(Some(*from), |up| rise(from, &up))?,
                rise(to, up)?,
            );
            let between =
                self.free
                    .connect(&high_from, &high_to, seed, self.settings.rrt_max_samples)?;
            let sampled = between.len() > 2;
            Some(([vec![*from], between, vec![*to]].concat(), sampled))
        };
        over().filter(|(path, _)| clear(path)).or_else(|| {
            let path = self
                .free
                .connect(from, to, seed, self.settings.rrt_max_samples)?;
            clear(&path).then_some((path, true))
        })
    }

    /// The free move from `last` (above the last part) back to `home` that keeps the pen-up
    /// clearance ([`FreeSpace::move_free`]): the sampled move between them, else from `last`
    /// risen [`CLEARANCE_LIFT_M`] further; `None` where neither is found.
    pub(super) fn home_move(
        &self,
        last: &JointVector,
        home: &JointVector,
        seed: u64,
    ) -> Option<Vec<JointVector>> {
        let clear = |path: &Vec<JointVector>| self.free.move_free(path, self.pen_up_clearance_m());
        let samples = self.settings.rrt_max_samples;
        self.free
            .connect(last, home, seed, samples)
            .filter(clear)
            .or_else(|| {
                let robot = self.free.robot();
                let tip = robot.forward(last).tcp();
                let up = self
                    .free
                    .surfaces()
                    .iter()
                    .min_by(|a, b| {
                        ((tip - a.p0).dot(&a.n).abs()).total_cmp(&(tip - b.p0).dot(&b.n).abs())
                    })
                    .map(|surface| -surface.n)?;
                let high = self
                    .free
                    .reach_point(last, &(tip + up * CLEARANCE_LIFT_M))?;
                let path = self.free.connect(&high, home, seed, samples)?;
                Some([vec![*last], path].concat()).filter(clear)
            })
    }

    /// The joint-space polyline from `from` to `to` (both lifted above the part, which the tool
    /// leaves along `up`) whose edges are free and keep the pen-up clearance
    /// ([`FreeSpace::move_free`]): the straight edge where it does; else, where the edge sags,
    /// through the configuration near the middle of the edge whose tip lies midway between the
    /// two tips and the clearance higher ([`FreeSpace::reach_point`]), so that a blend rounding
    /// it keeps clear too, each half held up the same way, `depth` halvings at most.
    fn held_up(
        &self,
        from: &JointVector,
        to: &JointVector,
        up: &Vec3,
        depth: usize,
    ) -> Option<Vec<JointVector>> {
        if self
            .free
            .move_free(&[*from, *to], self.pen_up_clearance_m())
        {
            return Some(vec![*from, *to]);
        }
        if depth == 0 {
            return None;
        }
        let robot = self.free.robot();
        let tips = (robot.forward(from).tcp() + robot.forward(to).tcp()) / 2.0
            + up * self.pen_up_clearance_m();
        let middle = self.free.reach_point(&((from + to) / 2.0), &tips)?;
        let mut path = self.held_up(from, &middle, up, depth - 1)?;
        path.pop();
        path.extend(self.held_up(&middle, to, up, depth - 1)?);
        Some(path)
    }

    /// How high (m) the tool's tip stays above the part along a pen-up move, but on the lift
    /// and the set-down ([`PEN_UP_CLEARANCE_SHARE`] of the lift).
    fn pen_up_clearance_m(&self) -> f64 {
        PEN_UP_CLEARANCE_SHARE * self.settings.lift()
    }

    /// Appends the pen-up move between two parts (or after the last): `retreat` (the lift off
    /// the last part), `travel` (the free move from above it, or from the program's start) and
    /// `approach` (the set-down onto the next part) as one motion through their vertices with
    /// its corners rounded ([`time_blended_move`], each corner's arc starting
    /// [`BLEND_SHARE`] of the shorter edge before it), where that motion is free and keeps the
    /// pen-up clearance ([`FreeSpace::move_free`]) and holds the limits: one `travel` segment, at rest only where
    /// the tool leaves and meets the part. Else each of them rest to rest, at rest at every
    /// vertex.
    pub(super) fn join(
        &self,
        program: &mut Program,
        retreat: Option<[JointVector; 2]>,
        travel: &[JointVector],
        approach: Option<[JointVector; 2]>,
        dof: usize,
    ) {
        let mut vertices: Vec<JointVector> = Vec::new();
        for q in retreat
            .iter()
            .flatten()
            .chain(travel)
            .chain(approach.iter().flatten())
        {
            if vertices.last().is_none_or(|last| (q - last).norm() > 1e-12) {
                vertices.push(*q);
            }
        }
        let request = self.timing.request();
        let blended = (retreat.is_some() && vertices.len() > 2)
            .then(|| time_blended_move(&vertices, request, BLEND_SHARE))
            .flatten()
            .filter(|timed| {
                let path: Vec<JointVector> = timed.samples.iter().map(|s| s.q).collect();
                self.free.move_free(&path, self.pen_up_clearance_m())
            });
        let hop = match (retreat, travel, approach) {
            (Some(retreat), [_, _], Some(approach)) => self.hop(retreat, approach),
            _ => None,
        };
        let last_time =
            |timed: &emg_timing::TimedMove| timed.samples[timed.samples.len() - 1].time_ns;
        let quickest = match (blended, hop) {
            (Some(blended), Some(hop)) if last_time(&hop) < last_time(&blended) => Some(hop),
            (blended, hop) => blended.or(hop),
        };
        if let Some(timed) = quickest {
            let (definition, samples) = (&timed.definition, &timed.samples);
            program.append(SegmentKind::Travel, definition, samples, None, dof);
            return;
        }
        if let Some(retreat) = retreat {
            program.append_move(SegmentKind::Retreat, &retreat, self.timing, dof);
        }
        if !travel.is_empty() {
            program.append_move(SegmentKind::Travel, travel, self.timing, dof);
        }
        if let Some(approach) = approach {
            program.append_move(SegmentKind::Approach, &approach, self.timing, dof);
        }
    }

    /// The short pen-up move from the end of one part to the start of the next on the same
    /// surface as one hop: up and over through the configuration above the middle between
    /// them and straight down, the corner rounded ([`time_blended_move`]), the tool rising
    /// [`HOP_RISE`] of the lateral distance (at least the lift `retreat` and `approach` take,
    /// at most [`MAX_HOP_RISE_LIFTS`] lifts); `None` where the parts lie on different surfaces,
    /// lie further apart, or the hop is not free or comes nearer the part than the pen-up
    /// clearance off the lift and the set-down ([`FreeSpace::move_free`]).
    fn hop(
        &self,
        [end, above_end]: [JointVector; 2],
        [above_start, start]: [JointVector; 2],
    ) -> Option<emg_timing::TimedMove> {
        let robot = self.free.robot();
        let tcp = |q: &JointVector| robot.forward(q).tcp();
        let (from, to) = (tcp(&end), tcp(&start));
        let (lift_end, lift_start) = (tcp(&above_end) - from, tcp(&above_start) - to);
        let up = lift_end.try_normalize(1e-12)?;
        let across = to - from;
        let tolerance = self.free.constraints().line_tolerance_m;
        if (lift_start.try_normalize(1e-12)? - up).norm() > 1e-6
            || up.dot(&across).abs() > 2.0 * tolerance
        {
            return None;
        }
        let lift = lift_end.norm().min(lift_start.norm());
        // The distance from `origin` across the surface.
        let lateral = |point: &Vec3, origin: &Vec3| {
            let offset = point - origin;
            (offset - up * up.dot(&offset)).norm()
        };
        let distance = lateral(&to, &from);
        let rise = (HOP_RISE * distance).max(lift);
        if rise > MAX_HOP_RISE_LIFTS * lift {
            return None;
        }
        let middle = (above_end + above_start) / 2.0;
        let top = self
            .free
            .reach_point(&middle, &((from + to) / 2.0 + up * rise))?;
        let timed = time_blended_move(&[end, top, start], self.timing.request(), HOP_BLEND_SHARE)?;
        let path: Vec<JointVector> = timed.samples.iter().map(|s| s.q).collect();
        self.free
            .move_free(&path, self.pen_up_clearance_m())
            .then_some(timed)
    }

    /// `part`'s stretch planned again by one rollout from the configuration reached from
    /// `from` (lifted, above the part's start) by moving the tool straight above the start and
    /// down onto it, the arm keeping its branch: at the tool's lift, else risen
    /// [`CLEARANCE_LIFT_M`] higher first (over what a low move would graze); `None` where
    /// neither move is free.
    pub(super) fn replanned_nearby(
        &self,
        planner: &Planner,
        request: &PlanRequest,
        part: &StrokePart,
        from: &JointVector,
    ) -> Option<StrokePart> {
        let robot = self.free.robot();
        let start_point = part.task.p0;
        let up = -part.task.n;
        let above = self
            .free
            .reach_point(from, &(start_point + up * self.settings.lift()))
            .or_else(|| {
                let high = self
                    .free
                    .reach_point(from, &(robot.forward(from).tcp() + up * CLEARANCE_LIFT_M))?;
                let over = self
                    .free
                    .reach_point(&high, &(start_point + up * CLEARANCE_LIFT_M))?;
                self.free
                    .reach_point(&over, &(start_point + up * self.settings.lift()))
            })?;
        let start = self.free.reach_point(&above, &start_point)?;
        let rollout = PlanRequest {
            planner: emg_planner::PlannerKind::Controller,
            seed: Some(emg_planner::SeedSource::Given(
                robot.joints_of(&start).to_vec(),
            )),
            controller: request.controller,
        };
        let planned = planner.plan(&part.task, &rollout).ok()?;
        (planned.trajectory.steps.len() > 1).then(|| StrokePart {
            from_s: part.from_s,
            backward: part.backward,
            task: part.task.clone(),
            trajectory: planned.trajectory,
        })
    }
}
