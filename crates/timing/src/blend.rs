//! A move through free space that does not stop at its inner vertices: each corner of the joint
//! polyline rounded by a circular arc in joint space, tangent to both edges and starting at most
//! a given share of the shorter edge before the vertex, the whole path timed at once from rest to
//! rest (TOPP-RA within the joint velocity and acceleration limits, averaged over the window the
//! jerk limits need and slowed down locally where a sample still breaks a limit, as a stroke is
//! timed). The path leaves the checked polyline, so whoever uses it checks its samples again.

use emg_kinematics::JointVector;

use crate::blended_path::{BlendedPath, Piece};
use crate::dynamics::breaches;
use crate::free::{FREE_GRID_PER_RAD, TimedMove};
use crate::motion::MotionDefinition;
use crate::retime::{MAX_SLOWDOWNS, TimingRequest, planned_profile, slow_down};
use crate::topp::GridPoint;

/// Grid intervals along a blend at least.
const GRID_PER_BLEND: f64 = 40.0;

/// An inner vertex closer than this (rad, in its largest joint) to the vertex before it is the
/// same configuration: an edge that short would be rounded by blends too small for the
/// samples' velocities to integrate to their positions.
pub const SAME_VERTEX_RAD: f64 = 1e-4;

/// `vertices` without the inner ones within [`SAME_VERTEX_RAD`] of the vertex kept before them;
/// the ends stay (the last in place of an inner vertex that close to it).
fn distinct(vertices: &[JointVector]) -> Vec<JointVector> {
    let mut kept: Vec<JointVector> = Vec::with_capacity(vertices.len());
    for (index, q) in vertices.iter().enumerate() {
        let is_last = index + 1 == vertices.len();
        let inner_before = kept.len() > 1;
        match kept.last_mut() {
            Some(previous) if (q - *previous).amax() < SAME_VERTEX_RAD => {
                if is_last && inner_before {
                    *previous = *q;
                } else if is_last {
                    kept.push(*q);
                }
            }
            _ => kept.push(*q),
        }
    }
    kept
}

/// The rest-to-rest motion at `request.rate_hz` along the polyline `vertices` with every corner
/// rounded (each arc starting `share` ≤ ½ of the shorter of its edges before its vertex), not
/// stopping at any inner vertex, inner vertices within [`SAME_VERTEX_RAD`] of the one before
/// them taken as one; `None` where a corner turns back (more than
/// [`MAX_BLEND_TURN_DEG`](crate::MAX_BLEND_TURN_DEG)) or the samples break a limit after
/// [`MAX_SLOWDOWNS`] local slow-downs.
pub fn time_blended_move(
    vertices: &[JointVector],
    request: &TimingRequest,
    share: f64,
) -> Option<TimedMove> {
    let share = share.clamp(0.0, 0.5);
    let vertices = distinct(vertices);
    let path = BlendedPath::new(&vertices, share)?;
    let mut grid = Vec::new();
    let limits = &request.limits;
    let (velocity, jerk) = (&limits.velocity, &limits.jerk);
    for (piece, at) in path.pieces.iter().zip(&path.starts) {
        let length = piece.length();
        let per_m = match piece {
            Piece::Line { .. } => FREE_GRID_PER_RAD,
            Piece::Blend { length, .. } => FREE_GRID_PER_RAD.max(GRID_PER_BLEND / length),
        };
        let intervals = ((length * per_m).ceil() as usize).max(2);
        let skip = usize::from(!grid.is_empty());
        for i in skip..=intervals {
            let local = length * i as f64 / intervals as f64;
            let (_, dq, ddq) = piece.eval(local);
            // The path's third derivative (by central differences on a blend): the jerk
            // `q'''·ṡ³` it adds stays within half the limit.
            let dddq = match piece {
                Piece::Line { .. } => JointVector::zeros(),
                Piece::Blend { length, .. } => {
                    let h = 1e-4 * length;
                    let ahead = piece.eval((local + h).min(*length)).2;
                    let behind = piece.eval((local - h).max(0.0)).2;
                    (ahead - behind) / ((local + h).min(*length) - (local - h).max(0.0))
                }
            };
            let speed_bound = (0..dq.len())
                .filter(|&j| dq[j].abs() > 1e-12)
                .map(|j| velocity[j] / dq[j].abs())
                .chain(
                    (0..dq.len())
                        .filter(|&j| dddq[j].abs() > 1e-12)
                        .map(|j| libm::cbrt(0.5 * jerk[j] / dddq[j].abs())),
                )
                .fold(f64::INFINITY, f64::min);
            grid.push(GridPoint {
                s: *at + local,
                dq,
                ddq,
                x_max: speed_bound * speed_bound,
            });
        }
    }
    if grid.len() < 2 {
        return None;
    }
    let s: Vec<f64> = grid.iter().map(|g: &GridPoint| g.s).collect();
    // As a stroke is timed: averaged over the window the jerk limits need at full acceleration,
    // slowed down locally wherever a sample still breaks a limit.
    let window = 2.0
        * limits
            .acceleration
            .iter()
            .zip(limits.jerk.iter())
            .filter(|(_, j)| **j > 0.0)
            .map(|(a, j)| a / j)
            .fold(0.0, f64::max);
    let mut factor = vec![1.0; grid.len()];
    for _ in 0..=MAX_SLOWDOWNS {
        let profile = planned_profile(&grid, &s, limits, &factor, window);
        let smoothed = profile.smoothed();
        let samples = path.samples(&smoothed, request.rate_hz);
        let found = breaches(&samples, limits);
        if found.is_empty() {
            return Some(TimedMove {
                samples,
                definition: MotionDefinition::Blended {
                    vertices,
                    share,
                    profile,
                },
            });
        }
        slow_down(
            &mut factor,
            &grid,
            &smoothed,
            &samples,
            &found,
            request.rate_hz,
        );
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::free::tests::{assert_samples, assert_velocities_match_positions, request};
    use crate::{first_breach, time_free_move};

    /// Distance of `q` from the polyline `vertices`.
    fn off_polyline(q: &JointVector, vertices: &[JointVector]) -> f64 {
        vertices
            .windows(2)
            .map(|edge| {
                let chord = edge[1] - edge[0];
                let t = ((q - edge[0]).dot(&chord) / chord.norm_squared()).clamp(0.0, 1.0);
                (q - (edge[0] + chord * t)).norm()
            })
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn a_blended_move_rounds_its_corners_without_stopping_and_holds_the_limits() {
        let request = request();
        let a = JointVector::zeros();
        let mut b = a;
        b[2] = 0.1;
        let mut c = b;
        c[0] = 1.0;
        c[3] = -0.5;
        let mut d = c;
        d[2] = 0.0;
        let vertices = [a, b, c, d];
        let share = 0.5;
        let samples = time_blended_move(&vertices, &request, share)
            .expect("a blended move")
            .samples;
        let (first, last) = (samples[0], samples[samples.len() - 1]);
        assert_eq!((first.q, last.q), (a, d));
        assert_eq!(
            (first.qd, last.qd),
            (JointVector::zeros(), JointVector::zeros())
        );
        assert_eq!(first_breach(&samples, &request.limits), None);
        // It keeps near the polyline: within the largest corner cut of it, and it never comes
        // to rest between its ends.
        for sample in &samples[1..samples.len() - 1] {
            assert!(off_polyline(&sample.q, &vertices) <= share * 0.1 + 1e-9);
            assert!(sample.qd.norm() > 0.0);
        }
        assert_velocities_match_positions(&samples);
        // The samples the move's timing gave before programs kept its definition instead.
        assert_samples(
            &samples,
            2566,
            &[
                (
                    582,
                    [
                        [0.020672178868354416, 0.0, -0.010336089434177208],
                        [0.21574309536045663, 0.0, -0.10787154768022832],
                        [0.5979789868631116, 0.0, -0.2989894934315558],
                    ],
                ),
                (
                    1164,
                    [
                        [0.3507111631839721, 0.0, -0.17535558159198605],
                        [0.8944271909999171, 0.0, -0.44721359549995854],
                        [0.0, 0.0, 0.0],
                    ],
                ),
                (
                    1746,
                    [
                        [0.8595202555740978, 0.0, -0.4297601277870489],
                        [0.7012069419113979, 0.0, -0.35060347095569894],
                        [-2.1201463091756025, 0.0, 1.0600731545878013],
                    ],
                ),
                (2565, [[1.0, 0.0, -0.5], [0.0; 3], [0.0; 3]]),
            ],
        );
        // Faster than stopping at every vertex.
        let stopping = time_free_move(&vertices, &request).samples;
        assert!(last.time_ns < stopping[stopping.len() - 1].time_ns);
    }

    #[test]
    fn a_lift_and_set_down_at_one_place_are_not_blended_through_a_vanishing_edge() {
        // A pen lifted off one stroke's end and set down on the next's start at the same
        // point: the two tops of the move 6e-6 rad apart (a program of Hershey lettering). The
        // blend of so short an edge once gave samples whose velocities did not integrate to
        // their positions within what the checker allows.
        let vertex = |q: [f64; 7]| JointVector::from_column_slice(&q);
        let vertices = [
            vertex([
                0.0747457780446972,
                -0.19079027368490095,
                0.04309616331353966,
                -2.205655957703459,
                -0.008725147775713671,
                1.9010106634716988,
                std::f64::consts::FRAC_PI_4,
            ]),
            vertex([
                0.07477564611980778,
                -0.19457718605336793,
                0.04309877508703792,
                -2.2047649524678126,
                -0.008726981635044737,
                1.8988938255101038,
                std::f64::consts::FRAC_PI_4,
            ]),
            vertex([
                0.0747765175241638,
                -0.19457775090345727,
                0.04310009378660151,
                -2.2047664435106897,
                -0.008726148038853526,
                1.8988962168610626,
                std::f64::consts::FRAC_PI_4,
            ]),
            vertex([
                0.07474664867873766,
                -0.19079083558584417,
                0.04309748263309584,
                -2.205657445865117,
                -0.008724314157741657,
                1.9010130563672234,
                std::f64::consts::FRAC_PI_4,
            ]),
        ];
        let request = TimingRequest {
            limits: crate::limits::DynamicLimits {
                velocity: JointVector::from_column_slice(&[
                    2.62, 2.62, 2.62, 2.62, 5.26, 4.18, 5.26,
                ]),
                acceleration: JointVector::repeat(10.0),
                jerk: JointVector::repeat(5000.0),
            },
            tool_speed_m_per_s: 0.2,
            rate_hz: 1000.0,
        };
        // Its two tops taken as one, the move turns back there: it is not blended (the job lifts
        // and sets down at rest instead).
        assert!(time_blended_move(&vertices, &request, 0.4).is_none());
    }

    #[test]
    fn a_move_that_turns_back_is_not_blended() {
        let a = JointVector::zeros();
        let mut b = a;
        b[0] = 0.5;
        let mut c = a;
        c[1] = 0.01;
        assert!(time_blended_move(&[a, b, c], &request(), 0.5).is_none());
    }
}
