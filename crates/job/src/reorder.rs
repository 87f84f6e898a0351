//! The reorder stage: the strokes' order changed where the estimated pen-up time, not the
//! travel, says so.
//!
//! The order stage ([`crate::order`]) shortens the pen-up travel before any stroke is planned.
//! Where every move of the arm takes a time that grows with its travel (strokes on one surface,
//! drawn on one branch), that order is also the quickest. Where it does not, it can be far from
//! it: between strokes on two faces of a part, a short hop across the edge turns the tool over
//! from one face's normal to the other's, which takes the wrist longer than a longer move along
//! one face; between strokes on different branches, a short hop may turn a joint half a turn.
//! Once the strokes are planned and connected, each one's start and end configurations are
//! known, and with them the estimated time of every pen-up move: the time-optimal rest-to-rest
//! joint motion between them at the arm's limits (the estimate of the choose-branches stage,
//! [`crate::branch`]). The same local search as the order stage's ([`Tour`]) then moves runs of
//! strokes (each in the direction it is drawn in: a stroke's configurations are known only that
//! way round) among each stroke end's [`NEIGHBOURS`] nearest ends, to lower the estimated
//! pen-up time of the whole job, from the home and back to it.

use emg_kinematics::{JointVector, Vec3};

use crate::branch::Branches;
use crate::order::near::{Grid, NEIGHBOURS};
use crate::order::oriented::Oriented;
use crate::order::tour::{Legs, Tour};

/// The least estimated pen-up time (s) a new order must save to be connected: below it, the
/// time a connect takes is not worth what the estimate promises.
pub const MIN_SAVED_S: f64 = 0.01;

/// The strokes' new order, as places in the order they are drawn in now, where it lowers the
/// estimated pen-up time by more than [`MIN_SAVED_S`] (the module's description), with the
/// estimated times before and after (s); `None` where no order found does. `placed` is where
/// each stroke's first part starts and its last ends as [`Branches::ends`] holds them (`None`
/// where none was placed: such strokes go last, in their order), `points` where its stroke starts
/// and ends, and `home` where the arm starts and ends, if anywhere. Deterministic.
pub fn reorder_by_move_time(
    placed: &[Option<[JointVector; 2]>],
    points: &[[Vec3; 2]],
    home: Option<&JointVector>,
    job: &impl Branches,
) -> Option<(Vec<usize>, [f64; 2])> {
    let drawn: Vec<usize> = (0..placed.len()).filter(|&i| placed[i].is_some()).collect();
    let legs = MoveTimes {
        ends: drawn
            .iter()
            .map(|&i| placed[i].expect("a drawn stroke has ends"))
            .collect(),
        home,
        job,
    };
    let neighbours = legs.nearest_ends(&drawn.iter().map(|&i| points[i]).collect::<Vec<_>>());
    let as_drawn = (0..drawn.len())
        .map(|stroke| Oriented {
            stroke,
            reversed: false,
        })
        .collect();
    let mut tour = Tour::new(&legs, as_drawn, neighbours);
    let before_s = tour.cost();
    tour.improve();
    let after_s = tour.cost();
    if after_s > before_s - MIN_SAVED_S {
        return None;
    }
    let order = tour
        .sequence
        .iter()
        .map(|oriented| drawn[oriented.stroke])
        .chain((0..placed.len()).filter(|&i| placed[i].is_none()))
        .collect();
    Some((order, [before_s, after_s]))
}

/// `items` in `order` (places in `items`).
pub fn in_order<T: Clone>(items: &[T], order: &[usize]) -> Vec<T> {
    order.iter().map(|&i| items[i].clone()).collect()
}

/// The estimated pen-up times between strokes drawn as placed: stroke i's start is point 2i,
/// its end 2i + 1.
struct MoveTimes<'a, B: Branches> {
    ends: Vec<[JointVector; 2]>,
    home: Option<&'a JointVector>,
    job: &'a B,
}

impl<B: Branches> MoveTimes<'_, B> {
    /// The configuration at stroke end `point`.
    fn at(&self, point: usize) -> &JointVector {
        &self.ends[point / 2][point % 2]
    }

    /// Each stroke end's [`NEIGHBOURS`] nearest ends of the other kind (a start's ends, an
    /// end's starts) of other strokes, at `points` (each stroke's start and end), least
    /// estimated pen-up time first, with their times.
    fn nearest_ends(&self, points: &[[Vec3; 2]]) -> Vec<Vec<(f64, usize)>> {
        let mut grid = Grid::new(points.iter().flatten().copied().collect());
        (0..2 * points.len())
            .map(|point| {
                let at = grid.point(point);
                let near = grid.nearest(at, NEIGHBOURS, f64::INFINITY, |other| {
                    other / 2 != point / 2 && other % 2 != point % 2
                });
                let mut timed: Vec<(f64, usize)> = near
                    .into_iter()
                    .map(|(_, other)| (self.job.move_s(self.at(point), self.at(other)), other))
                    .collect();
                timed.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                timed
            })
            .collect()
    }
}

impl<B: Branches> Legs for MoveTimes<'_, B> {
    fn cost(&self, from: Option<usize>, to: Option<usize>) -> f64 {
        let from = from.map(|point| self.at(point)).or(self.home);
        let to = to.map(|point| self.at(point)).or(self.home);
        from.zip(to)
            .map_or(0.0, |(from, to)| self.job.move_s(from, to))
    }

    fn reversible(&self, _stroke: usize) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stroke::StrokePlan;

    /// Strokes on two faces: each move takes its largest joint difference, and turning the
    /// wrist (joint 5) over to the other face takes a second.
    struct TwoFaces;

    impl Branches for TwoFaces {
        fn ends(&self, _plan: &StrokePlan) -> Option<[JointVector; 2]> {
            None
        }

        fn carried(&self, _: &StrokePlan, _: usize, _: &JointVector) -> Option<StrokePlan> {
            None
        }

        fn move_s(&self, from: &JointVector, to: &JointVector) -> f64 {
            (from - to).amax()
        }
    }

    /// Stroke `k` of six pairs listed face by face in turn: a short stroke along y at x =
    /// 0.05 (k / 2), on the level face (even k, the wrist at 0) or the rising one (odd k, the
    /// wrist at 1 rad, 4 cm away across the edge); joint 0 follows x.
    fn stroke(k: usize) -> ([Vec3; 2], [JointVector; 2]) {
        let x = 0.05 * (k / 2) as f64;
        // Each stroke runs 1 cm from 2 cm off the edge (y = 0) away from it.
        let (side, wrist) = if k.is_multiple_of(2) {
            (-1.0, 0.0)
        } else {
            (1.0, 1.0)
        };
        let at = |y: f64| {
            let mut q = JointVector::zeros();
            (q[0], q[1], q[5]) = (x, y, wrist);
            q
        };
        let (start, end) = (0.02 * side, 0.03 * side);
        (
            [Vec3::new(x, start, 0.0), Vec3::new(x, end, 0.0)],
            [at(start), at(end)],
        )
    }

    #[test]
    fn strokes_alternating_between_faces_are_drawn_one_face_then_the_other() {
        let (points, ends): (Vec<[Vec3; 2]>, Vec<[JointVector; 2]>) = (0..12).map(stroke).unzip();
        let mut placed: Vec<Option<[JointVector; 2]>> = ends.into_iter().map(Some).collect();
        // One stroke no part of which was placed: it plays no part, and goes last.
        placed[4] = None;
        let home = JointVector::zeros();
        let (order, [before_s, after_s]) =
            reorder_by_move_time(&placed, &points, Some(&home), &TwoFaces).expect("reordered");
        assert_eq!(order.len(), 12);
        assert_eq!(order[11], 4);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..12).collect::<Vec<_>>());
        // As listed, the wrist turns over between every pair of strokes; reordered, once (and
        // back home).
        let changes = order[..11]
            .windows(2)
            .filter(|pair| pair[0] % 2 != pair[1] % 2)
            .count();
        assert_eq!(changes, 1, "{order:?}");
        assert!(before_s > 9.0 && after_s < 3.0, "{before_s} → {after_s}");
        // The estimate after is the sum of the reordered moves, home to home.
        let at = |i: usize| placed[i].expect("placed");
        let drawn = &order[..11];
        let inner: f64 = drawn
            .windows(2)
            .map(|pair| TwoFaces.move_s(&at(pair[0])[1], &at(pair[1])[0]))
            .sum();
        let total = TwoFaces.move_s(&home, &at(drawn[0])[0])
            + inner
            + TwoFaces.move_s(&at(drawn[10])[1], &home);
        assert!((total - after_s).abs() < 1e-12, "{total} against {after_s}");
    }

    #[test]
    fn strokes_already_in_the_quickest_order_are_left_alone() {
        // One face only: the order as listed (along x) is the quickest.
        let (points, ends): (Vec<[Vec3; 2]>, Vec<[JointVector; 2]>) =
            (0..6).map(|k| stroke(2 * k)).unzip();
        let placed: Vec<_> = ends.into_iter().map(Some).collect();
        let home = JointVector::zeros();
        assert!(reorder_by_move_time(&placed, &points, Some(&home), &TwoFaces).is_none());
    }
}
