//! A motion that dips into an obstacle, the work plate or the arm's own links at a single
//! sample, clear at every other, fails at that very sample: the checker's cheap bounds that
//! spare it exact measures never let a contact through.

use emg_verify::{
    Bounds, FailedCheck, JointSamples, Joints, Line, Obstacle, ReferenceModel, ReplayCheck,
    ReplayError, Solid, Surface, check_replay,
};
use nalgebra::{Matrix3, Vector3};

fn fr3() -> ReferenceModel {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fr3_pen.urdf");
    ReferenceModel::from_urdf_file(&path, "link0", "pen_tip").expect("the shipped robot")
}

/// A pose above the table, the pen pointing down.
fn home() -> Joints {
    Joints::from_column_slice(&[0.0, -0.3, 0.0, -2.2, 0.0, 1.9, 0.8])
}

/// 1 kHz samples from `home` turning joint 1 slowly (0.2 rad/s), with sample `dip` replaced
/// by `dipped`.
fn motion(count: usize, dip: usize, dipped: Joints) -> JointSamples {
    let time_s: Vec<f64> = (0..count).map(|k| k as f64 * 1e-3).collect();
    let q = time_s
        .iter()
        .enumerate()
        .map(|(k, t)| {
            if k == dip {
                dipped
            } else {
                let mut q = home();
                q[0] += 0.2 * t;
                q
            }
        })
        .collect();
    JointSamples {
        time_s,
        q,
        qd: None,
        qdd: None,
    }
}

/// Bounds that hold the line and the cone wherever the tool goes and leave joint speeds free,
/// so that only contacts can fail.
fn contact_bounds(work_surface: Option<Surface>, obstacles: Vec<Obstacle>) -> Bounds {
    Bounds {
        line_tolerance_m: f64::INFINITY,
        theta_max_deg: 180.0,
        collision_margin_m: 0.0,
        velocity_limit_fraction: None,
        work_surface,
        obstacles,
    }
}

/// The check fails at sample `dip` with `expected`, while the samples before it pass.
fn fails_at_the_dip(
    model: &ReferenceModel,
    line: &Line,
    bounds: &Bounds,
    samples: &JointSamples,
    dip: usize,
    expected: FailedCheck,
) {
    let before = JointSamples {
        time_s: samples.time_s[..dip].to_vec(),
        q: samples.q[..dip].to_vec(),
        qd: None,
        qdd: None,
    };
    check_replay(model, line, bounds, &before, None, None).expect("clear before the dip");
    let after = JointSamples {
        time_s: samples.time_s[dip + 1..].iter().map(|t| t - 1.0).collect(),
        q: samples.q[dip + 1..].to_vec(),
        qd: None,
        qdd: None,
    };
    check_replay(model, line, bounds, &after, None, None).expect("clear after the dip");
    match check_replay(model, line, bounds, samples, None, None) {
        Err(ReplayError::Point { point, check, .. }) => {
            assert_eq!((point, check), (dip, ReplayCheck::Recording(expected)));
        }
        other => panic!("the dip at sample {dip} is not caught: {other:?}"),
    }
}

/// The dipped configuration: `home` with the elbow (joint 4) opened by `by` rad, which lowers
/// the tool by centimetres.
fn lowered(by: f64) -> Joints {
    let mut q = home();
    q[0] += 0.2 * 0.5;
    q[3] += by;
    q
}

#[test]
fn a_single_sample_inside_an_obstacle_fails_there() {
    let model = fr3();
    let (tcp, axis) = model.tcp_pose(&home());
    let line = Line::straight(tcp, axis.cross(&Vector3::x()).normalize(), axis);
    let dip = 500;
    let dipped = lowered(0.3);
    let (low_tcp, _) = model.tcp_pose(&dipped);
    // A small ball where the dipped tool's tip is, and a box around it: each holds that one
    // sample only (the tip moves 0.2 mm a sample elsewhere, centimetres above).
    for solid in [
        Solid::Ball {
            centre: low_tcp,
            radius: 0.005,
        },
        Solid::Box {
            centre: low_tcp,
            axes: Matrix3::identity(),
            half_extents: Vector3::new(0.01, 0.01, 0.005),
        },
        Solid::Capsule {
            a: low_tcp - Vector3::x() * 0.01,
            b: low_tcp + Vector3::x() * 0.01,
            radius: 0.004,
        },
    ] {
        let obstacle = Obstacle {
            name: "peg".into(),
            solid,
            clearance_m: 0.0,
            tool_may_touch: false,
        };
        let bounds = contact_bounds(None, vec![obstacle]);
        let samples = motion(1000, dip, dipped);
        fails_at_the_dip(
            &model,
            &line,
            &bounds,
            &samples,
            dip,
            FailedCheck::SceneContact,
        );
    }
}

#[test]
fn a_single_sample_through_the_work_plate_fails_there() {
    let model = fr3();
    // The dipped sample swung a radian aside and lowered, over a plate that lies away from
    // the rest of the motion.
    let mut dipped = lowered(0.6);
    dipped[0] += 1.0;
    let (low_tcp, _) = model.tcp_pose(&dipped);
    // A plate under the dipped tool, its top raised from the tool's tip (which may touch it)
    // until a link of the dipped arm is 1 mm into it.
    let n = -Vector3::z();
    let plate = Surface::Plate {
        half_width_m: 0.1,
        behind_m: 0.1,
        ahead_m: 0.1,
        thickness_m: 0.02,
    };
    let bounds = contact_bounds(Some(plate), Vec::new());
    let line = (0..300)
        .map(|mm| Line::straight(low_tcp - n * (1e-3 * f64::from(mm)), Vector3::x(), n))
        .find(|line| {
            model
                .scene_margin(&dipped, line, &bounds)
                .is_some_and(|(margin, ..)| margin < -1e-3)
        })
        .expect("a plate the dipped arm reaches into");
    let dip = 321;
    let samples = motion(700, dip, dipped);
    fails_at_the_dip(
        &model,
        &line,
        &bounds,
        &samples,
        dip,
        FailedCheck::SceneContact,
    );
}

#[test]
fn a_single_self_colliding_sample_fails_there() {
    let model = fr3();
    // A configuration within the limits whose links collide, drawn from a fixed stream.
    let mut state = 0x2545_F491_4F6C_DD1D_u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let limits = model.limits();
    let folded = (0..100_000)
        .map(|_| {
            let mut q = Joints::zeros();
            for (i, (lo, hi)) in limits.iter().enumerate() {
                q[i] = lo + (hi - lo) * next();
            }
            q
        })
        .find(|q| model.min_clearance(q).0 < -1e-3)
        .expect("a folded configuration collides");
    let (tcp, axis) = model.tcp_pose(&home());
    let line = Line::straight(tcp, axis.cross(&Vector3::x()).normalize(), axis);
    let dip = 17;
    let samples = motion(300, dip, folded);
    fails_at_the_dip(
        &model,
        &line,
        &contact_bounds(None, Vec::new()),
        &samples,
        dip,
        FailedCheck::SelfCollision,
    );
}
