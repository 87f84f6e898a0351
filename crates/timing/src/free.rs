//! The timing of a move through free space (the tool lifted between two strokes): a polyline in
//! joint space whose every edge was checked collision-free, so the motion keeps to the edges
//! exactly and comes to rest at each inner vertex. Each edge is timed from rest to rest,
//! time-optimal within the joint velocity and acceleration limits (TOPP-RA on the straight
//! edge) and jerk-limited by averaging that profile over the window its jerk bound needs.

use emg_kinematics::JointVector;

use crate::dynamics::TimedSample;
use crate::motion::{MotionDefinition, ProfileGrid, moving_edges};
use crate::retime::TimingRequest;
use crate::topp::{GridPoint, topp_ra};

/// Grid intervals of TOPP-RA per radian of an edge (the joint-space distance): the profile on a
/// straight edge is exact up to the grid's interpolation of its acceleration bounds.
pub const FREE_GRID_PER_RAD: f64 = 100.0;

/// A timed move through free space: its samples and what they are computed from.
#[derive(Clone, Debug)]
pub struct TimedMove {
    /// Samples at `k / rate` (rounded to whole nanoseconds), from rest to rest.
    pub samples: Vec<TimedSample>,
    /// What the samples are computed from ([`MotionDefinition::samples`] gives them again).
    pub definition: MotionDefinition,
}

/// The rest-to-rest motion along the polyline `vertices` at `request.rate_hz` (from rest at the
/// first to rest at the last, at rest at every inner vertex), every sample at a time `k / rate`
/// from 0. Edges shorter than 1e-9 rad are skipped; a single vertex is one sample at rest.
///
/// # Panics
///
/// If `vertices` is empty.
pub fn time_free_move(vertices: &[JointVector], request: &TimingRequest) -> TimedMove {
    assert!(!vertices.is_empty(), "a move has a vertex");
    let edges = moving_edges(vertices)
        .map(|(_, _, direction, length)| edge_profile(&direction, length, request))
        .collect();
    let definition = MotionDefinition::Polyline {
        vertices: vertices.to_vec(),
        edges,
    };
    TimedMove {
        samples: definition.samples(request.rate_hz),
        definition,
    }
}

/// The jerk-limited rest-to-rest profile along a straight edge of `length` rad in the unit
/// joint direction `direction`.
fn edge_profile(direction: &JointVector, length: f64, request: &TimingRequest) -> ProfileGrid {
    let limits = &request.limits;
    let speed_bound = (0..direction.len())
        .filter(|&j| direction[j].abs() > 1e-12)
        .map(|j| limits.velocity[j] / direction[j].abs())
        .fold(f64::INFINITY, f64::min);
    let intervals = ((length * FREE_GRID_PER_RAD).ceil() as usize).max(2);
    let grid: Vec<GridPoint> = (0..=intervals)
        .map(|i| GridPoint {
            s: length * i as f64 / intervals as f64,
            dq: *direction,
            ddq: JointVector::zeros(),
            x_max: speed_bound * speed_bound,
        })
        .collect();
    let x = topp_ra(&grid, &limits.acceleration, &vec![1.0; grid.len()]);
    let largest_sdd = grid
        .windows(2)
        .zip(x.windows(2))
        .map(|(g, x)| ((x[1] - x[0]) / (2.0 * (g[1].s - g[0].s))).abs())
        .fold(0.0, f64::max);
    // Averaging over `w` bounds the path jerk by `2 max|s̈| / w`; joint j's jerk is that times
    // `|direction_j|`.
    let window = (0..direction.len())
        .filter(|&j| direction[j].abs() > 1e-12)
        .map(|j| 2.0 * largest_sdd * direction[j].abs() / limits.jerk[j])
        .fold(1e-6, f64::max);
    ProfileGrid {
        s: grid.iter().map(|g| g.s).collect(),
        x,
        window_s: window,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::DynamicLimits;

    /// Limits of a seven-joint arm for the free moves' tests, at 1 kHz.
    pub(crate) fn request() -> TimingRequest {
        let mut velocity = JointVector::zeros();
        let mut acceleration = JointVector::zeros();
        let mut jerk = JointVector::zeros();
        for j in 0..7 {
            velocity[j] = 1.0 + 0.1 * j as f64;
            acceleration[j] = 3.0;
            jerk[j] = 30.0;
        }
        TimingRequest {
            limits: DynamicLimits {
                velocity,
                acceleration,
                jerk,
            },
            tool_speed_m_per_s: 0.2,
            rate_hz: 1000.0,
        }
    }

    /// The vertices `a`, `b`, `c` of the free move the tests time: from zero, joints 1 and 4
    /// turn, then joint 2.
    fn two_edges() -> [JointVector; 3] {
        let a = JointVector::zeros();
        let mut b = a;
        b[0] = 1.0;
        b[3] = -0.5;
        let mut c = b;
        c[1] = 0.4;
        [a, b, c]
    }

    #[test]
    fn a_free_move_keeps_its_edges_rests_at_its_vertices_and_holds_the_limits() {
        let request = request();
        let [a, b, c] = two_edges();
        let samples = time_free_move(&[a, b, c], &request).samples;
        assert_eq!(samples.first().unwrap().q, a);
        assert_eq!(samples.last().unwrap().q, c);
        assert_eq!(samples.last().unwrap().qd, JointVector::zeros());
        // The motion passes b at rest.
        let at_b = samples.iter().find(|s| s.q == b).expect("b is a sample");
        assert!(at_b.qd.norm() < 1e-9);
        for pair in samples.windows(2) {
            let dt = (pair[1].time_ns - pair[0].time_ns) as f64 * 1e-9;
            assert!(dt > 0.0 && dt <= 1e-3 + 1e-9);
            for j in 0..7 {
                assert!(pair[1].qd[j].abs() <= request.limits.velocity[j] * (1.0 + 1e-6));
                assert!(pair[1].qdd[j].abs() <= request.limits.acceleration[j] * (1.0 + 1e-3));
                let jerk = (pair[1].qdd[j] - pair[0].qdd[j]) / dt;
                assert!(jerk.abs() <= request.limits.jerk[j] * 1.05, "jerk {jerk}");
            }
            // On an edge: the sample lies on a straight line between two vertices.
            let q = pair[1].q;
            let on_ab = ((q - a).norm() + (b - q).norm() - (b - a).norm()).abs() < 1e-9;
            let on_bc = ((q - b).norm() + (c - q).norm() - (c - b).norm()).abs() < 1e-9;
            assert!(on_ab || on_bc, "{q:?} off the polyline");
        }
        assert_velocities_match_positions(&samples);
    }

    /// Asserts that `samples` has `count` samples, 1 ms apart, and that each of `expected`
    /// (index; joints 1, 2 and 4's position, velocity and acceleration) holds to 1e-9: the
    /// samples the move's timing gave before programs kept its definition instead.
    pub(crate) fn assert_samples(
        samples: &[TimedSample],
        count: usize,
        expected: &[(usize, [[f64; 3]; 3])],
    ) {
        assert_eq!(samples.len(), count);
        for (k, values) in expected {
            let sample = &samples[*k];
            assert_eq!(sample.time_ns, *k as u64 * 1_000_000);
            for (vector, values) in [sample.q, sample.qd, sample.qdd].iter().zip(values) {
                for (j, value) in [0, 1, 3].iter().zip(values) {
                    assert!((vector[*j] - value).abs() <= 1e-9, "sample {k}: {vector:?}");
                }
            }
        }
    }

    #[test]
    fn a_free_move_gives_the_samples_it_always_gave() {
        let timed = time_free_move(&two_edges(), &request());
        assert_samples(
            &timed.samples,
            2466,
            &[
                (
                    582,
                    [
                        [0.31530627481985096, 0.0, -0.15765313740992548],
                        [0.9999999999999994, 0.0, -0.4999999999999997],
                        [0.0, 0.0, 0.0],
                    ],
                ),
                (
                    1164,
                    [
                        [0.8862677824843519, 0.0, -0.44313389124217595],
                        [0.7982778133540263, 0.0, -0.3991389066770131],
                        [-2.4591882445955604, 0.0, 1.2295941222977802],
                    ],
                ),
                (
                    1746,
                    [
                        [1.0, 0.023815999999999973, -0.5],
                        [0.0, 0.3359999999999997, 0.0],
                        [0.0, 3.0, 0.0],
                    ],
                ),
                (2465, [[1.0, 0.4, -0.5], [0.0; 3], [0.0; 3]]),
            ],
        );
    }

    /// Asserts that every pair of samples' mean velocity is their positions' finite difference.
    pub(crate) fn assert_velocities_match_positions(samples: &[TimedSample]) {
        for pair in samples.windows(2) {
            let dt = (pair[1].time_ns - pair[0].time_ns) as f64 * 1e-9;
            let mean = (pair[1].q - pair[0].q) / dt;
            let average = (pair[1].qd + pair[0].qd) / 2.0;
            assert!((mean - average).norm() < 5e-3, "{mean:?} vs {average:?}");
        }
    }
}
