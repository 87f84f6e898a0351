//! What the programs for industrial controllers (an ABB RAPID module, a KUKA KRL program) share
//! besides their targets ([`crate::controller_targets`]): the part's frame their targets are
//! given in, the spacing held between a stroke's targets, and how numbers are written.

use nalgebra::{Isometry3, Rotation3, Translation3, UnitQuaternion};

use crate::controller_targets::Pose;
use crate::program::JobFile;

/// The closest two consecutive targets of a stroke may lie (m): closer targets leave the
/// controller's path planner no room for their corner zones.
pub const MIN_TARGET_SPACING_M: f64 = 1e-4;

/// The places in `kept` (indices of `poses`, the first where the tool stands) of the targets
/// written: every one after the first, but an inner one closer than [`MIN_TARGET_SPACING_M`]
/// to the last written (or to the start), and the inner one before the last where the last
/// lies that close to it (the stroke part comes to rest there: its last samples crowd).
pub(crate) fn spaced(poses: &[Pose], kept: &[usize]) -> Vec<usize> {
    let position = |n: usize| poses[kept[n]].position;
    let last = kept.len() - 1;
    let mut written: Vec<usize> = Vec::new();
    for n in 1..=last {
        let before = written.last().map_or(position(0), |&m| position(m));
        if n < last && (position(n) - before).norm() < MIN_TARGET_SPACING_M {
            continue;
        }
        if n == last
            && let Some(&m) = written.last()
            && (position(n) - position(m)).norm() < MIN_TARGET_SPACING_M
        {
            written.pop();
        }
        written.push(n);
    }
    written
}

/// The part's frame: the job's one work surface (origin its point, z out of the part along
/// `−n`, x along `d`), else the base frame.
pub(crate) fn part_frame(file: &JobFile) -> Isometry3<f64> {
    match file.surfaces.as_slice() {
        [surface] => {
            let z = -surface.n;
            let x = surface.d;
            let rotation = Rotation3::from_basis_unchecked(&[x, z.cross(&x), z]);
            Isometry3::from_parts(
                Translation3::from(surface.p0),
                UnitQuaternion::from_rotation_matrix(&rotation),
            )
        }
        _ => Isometry3::identity(),
    }
}

/// `value` with `decimals` decimals, without the sign of a value that rounds to zero.
pub(crate) fn fixed(value: f64, decimals: usize) -> String {
    let text = format!("{value:.decimals$}");
    match text.strip_prefix('-') {
        Some(magnitude) if magnitude.chars().all(|c| c == '0' || c == '.') => magnitude.to_string(),
        _ => text,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use emg_kinematics::Vec3;

    #[test]
    fn targets_closer_than_the_spacing_are_left_out_the_last_kept() {
        let poses: Vec<Pose> = [0.0, 0.05e-3, 0.3e-3, 0.35e-3, 0.6e-3, 0.65e-3]
            .iter()
            .map(|&x| Pose {
                position: Vec3::new(x, 0.0, 0.0),
                rotation: UnitQuaternion::identity(),
            })
            .collect();
        let kept: Vec<usize> = (0..poses.len()).collect();
        // 0.05 mm from the start: out; 0.35 after 0.3: out; the last, 0.05 after 0.6, in its
        // place.
        assert_eq!(spaced(&poses, &kept), vec![2, 5]);
    }

    #[test]
    fn a_number_that_rounds_to_zero_has_no_sign() {
        assert_eq!(fixed(-1e-12, 9), "0.000000000");
        assert_eq!(fixed(-0.0, 3), "0.000");
        assert_eq!(fixed(-0.25, 3), "-0.250");
        assert_eq!(fixed(12.5, 1), "12.5");
    }
}
