//! Jobs built in code, each showing one thing a job planner must get right; `cargo xtask
//! job-eval` plans them and the tests read them.

use emg_control::{PathSpec, SegmentSpec};
use emg_kinematics::Vec3;

/// Twelve seams 8 cm long across the edge (along the base's x, at y = 0 and z = 0.25 m) where
/// a level face (y < 0) meets one rising 40° from it (y > 0): six on each face at the same x,
/// 5 cm apart, each from 2 cm off the edge to 10 cm, pen down on its face. The shortest pen-up
/// travel goes back and forth across the edge, and every crossing turns the tool 40°.
pub fn valley_seams() -> Vec<PathSpec> {
    let rise = 40f64.to_radians();
    let level_normal = Vec3::new(0.0, 0.0, -1.0);
    let rising_normal = Vec3::new(0.0, libm::sin(rise), -libm::cos(rise));
    let up_level = Vec3::new(0.0, -1.0, 0.0);
    let up_rising = Vec3::new(0.0, libm::cos(rise), libm::sin(rise));
    let seam = |x: f64, away: Vec3, normal: Vec3, towards_edge: bool| {
        let edge = Vec3::new(x, 0.0, 0.25);
        let (near, far) = (edge + away * 0.02, edge + away * 0.1);
        let (start, end) = if towards_edge {
            (far, near)
        } else {
            (near, far)
        };
        PathSpec {
            version: emg_control::PATH_FORMAT_VERSION,
            start: start.into(),
            normal: normal.into(),
            blend_radius_m: 0.0,
            segments: vec![SegmentSpec::Line { to: end.into() }],
        }
    };
    (0..6)
        .flat_map(|k| {
            let x = 0.35 + 0.05 * k as f64;
            [
                seam(x, up_level, level_normal, true),
                seam(x, up_rising, rising_normal, false),
            ]
        })
        .collect()
}
