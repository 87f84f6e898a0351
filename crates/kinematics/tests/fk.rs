//! Forward kinematics of the shipped FR3-with-pen robot: the SPEC §1 known answers (q = 0 and
//! home), and agreement with an independent modified (Craig) DH computation, written here from
//! the SPEC's DH table, on 1,000 random configurations (TCP position, full TCP orientation and
//! every joint axis line); `forward_into` over another configuration's kinematics gives exactly
//! what `forward` gives. The six-joint UR5e file against Universal Robots' published standard DH
//! parameters, written here independently.

mod common;

use common::{home, random_q, rng, robot};
use emg_kinematics::{JointVector, Vec3};
use nalgebra::{Matrix3, Matrix4};
use std::f64::consts::FRAC_PI_2;

const DH_A: [f64; 7] = [0.0, 0.0, 0.0, 0.0825, -0.0825, 0.0, 0.088];
const DH_D: [f64; 7] = [0.333, 0.0, 0.316, 0.0, 0.384, 0.0, 0.0];
const DH_ALPHA: [f64; 7] = [
    0.0, -FRAC_PI_2, FRAC_PI_2, FRAC_PI_2, -FRAC_PI_2, FRAC_PI_2, FRAC_PI_2,
];
const FLANGE_D: f64 = 0.107;
const PEN_FROM_FLANGE: f64 = 0.2034;

fn rot_x(a: f64) -> Matrix4<f64> {
    let (s, c) = libm::sincos(a);
    Matrix4::new(
        1.0, 0.0, 0.0, 0.0, 0.0, c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0,
    )
}

fn rot_z(a: f64) -> Matrix4<f64> {
    let (s, c) = libm::sincos(a);
    Matrix4::new(
        c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    )
}

fn trans(x: f64, y: f64, z: f64) -> Matrix4<f64> {
    let mut t = Matrix4::identity();
    t[(0, 3)] = x;
    t[(1, 3)] = y;
    t[(2, 3)] = z;
    t
}

/// Modified-DH frames: element `i` is the frame of joint `i` (after its rotation), the last
/// element is the pen-tip frame.
fn dh_frames(q: &JointVector) -> Vec<Matrix4<f64>> {
    let mut t = Matrix4::identity();
    let mut frames = Vec::new();
    for i in 0..7 {
        t = t
            * rot_x(DH_ALPHA[i])
            * trans(DH_A[i], 0.0, 0.0)
            * rot_z(q[i])
            * trans(0.0, 0.0, DH_D[i]);
        frames.push(t);
    }
    frames.push(t * trans(0.0, 0.0, FLANGE_D + PEN_FROM_FLANGE));
    frames
}

fn position(t: &Matrix4<f64>) -> Vec3 {
    Vec3::new(t[(0, 3)], t[(1, 3)], t[(2, 3)])
}

fn rotation(t: &Matrix4<f64>) -> Matrix3<f64> {
    t.fixed_view::<3, 3>(0, 0).into_owned()
}

#[test]
fn zero_configuration_matches_spec() {
    let robot = robot();
    let q = JointVector::zeros();
    assert!(
        robot.limits().first_violation(&q, 0.0).is_some(),
        "q = 0 is outside the limits"
    );
    let kin = robot.forward(&q);
    let p_err = (kin.tcp() - Vec3::new(0.088, 0.0, 0.7226)).norm();
    let z_err = (kin.tool_axis() - Vec3::new(0.0, 0.0, -1.0)).norm();
    println!("q = 0: |p error| = {p_err:.3e}, |z error| = {z_err:.3e}");
    assert!(p_err < 1e-9, "tcp {:?}", kin.tcp());
    assert!(z_err < 1e-9, "tool axis {:?}", kin.tool_axis());
}

#[test]
fn home_configuration_matches_spec() {
    let robot = robot();
    let kin = robot.forward(&home());
    assert!(
        robot.limits().first_violation(&home(), 0.0).is_none(),
        "home is within the limits"
    );
    // The SPEC gives the home TCP to six decimals.
    let p_err = (kin.tcp() - Vec3::new(0.306891, 0.0, 0.386882)).amax();
    let z_err = (kin.tool_axis() - Vec3::new(0.0, 0.0, -1.0)).norm();
    println!("home: max |p error| = {p_err:.3e}, |z error| = {z_err:.3e}");
    assert!(p_err < 1e-6, "tcp {:?}", kin.tcp());
    assert!(z_err < 1e-9, "tool axis {:?}", kin.tool_axis());
    // The tool axis is the TCP rotation's third column and that rotation is orthonormal.
    let r = kin.tcp_rotation();
    assert!((r.transpose() * r - Matrix3::identity()).amax() < 1e-12);
    assert!((r.determinant() - 1.0).abs() < 1e-12);
}

#[test]
fn matches_independent_modified_dh_on_random_configurations() {
    let robot = robot();
    let mut rng = rng(0x0f0f_d1d1);
    let (mut worst_p, mut worst_z, mut worst_r, mut worst_axis) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for _ in 0..1000 {
        let q = random_q(&mut rng, &robot);
        let kin = robot.forward(&q);
        let frames = dh_frames(&q);
        let tip = &frames[7];
        worst_p = worst_p.max((kin.tcp() - position(tip)).norm());
        let tip_rotation = rotation(tip);
        worst_z = worst_z.max((kin.tool_axis() - tip_rotation.column(2)).norm());
        // The pen adds no rotation to link7: the whole TCP frame matches the DH frame 7.
        worst_r = worst_r.max((kin.tcp_rotation() - tip_rotation).amax());
        // Every joint turns about the DH frame's z axis, through a point on that axis line.
        for (i, frame) in frames.iter().take(7).enumerate() {
            let axis = rotation(frame).column(2).into_owned();
            let offset = kin.joint_origin(i) - position(frame);
            worst_axis = worst_axis
                .max((kin.joint_axis(i) - axis).norm())
                .max(offset.cross(&axis).norm());
        }
    }
    println!(
        "DH comparison (1,000 configs): tcp {worst_p:.3e} m, tool axis {worst_z:.3e}, \
         rotation {worst_r:.3e}, joint axes {worst_axis:.3e}"
    );
    assert!(worst_p < 1e-9, "tcp differs from DH by {worst_p:e}");
    assert!(worst_z < 1e-9, "tool axis differs from DH by {worst_z:e}");
    assert!(
        worst_r < 1e-9,
        "tcp rotation differs from DH by {worst_r:e}"
    );
    assert!(
        worst_axis < 1e-9,
        "joint axis lines differ from DH by {worst_axis:e}"
    );
}

#[test]
fn forward_into_over_other_kinematics_is_exactly_forward() {
    let robot = robot();
    let mut rng = rng(0x1e7f_0dd5);
    let mut kinematics = robot.forward(&random_q(&mut rng, &robot));
    for _ in 0..200 {
        let q = random_q(&mut rng, &robot);
        robot.forward_into(&q, &mut kinematics);
        // Debug prints every field, each f64 in its shortest exact form.
        assert_eq!(
            format!("{kinematics:?}"),
            format!("{:?}", robot.forward(&q))
        );
    }
}

#[test]
fn segment_frames_are_consistent_with_joint_axes_and_points() {
    let robot = robot();
    let mut rng = rng(77);
    for _ in 0..100 {
        let q = random_q(&mut rng, &robot);
        let kin = robot.forward(&q);
        for s in 1..=7 {
            let frame = kin.segment_frame(s);
            let local = Vec3::new(0.1, -0.2, 0.3);
            let via_frame = frame * nalgebra::Point3::from(local);
            assert!((via_frame.coords - kin.segment_point(s, &local)).norm() < 1e-12);
            assert!((frame.translation.vector - kin.joint_origin(s - 1)).norm() < 1e-12);
            assert!((frame.rotation * Vec3::z() - kin.joint_axis(s - 1)).norm() < 1e-12);
        }
    }
}

/// Universal Robots' published standard DH parameters of the UR5e (m, rad).
const UR5E_D: [f64; 6] = [0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996];
const UR5E_A: [f64; 6] = [0.0, -0.425, -0.3922, 0.0, 0.0, 0.0];
const UR5E_ALPHA: [f64; 6] = [FRAC_PI_2, 0.0, 0.0, FRAC_PI_2, -FRAC_PI_2, 0.0];

/// The flange pose of the UR5e at `q` by standard DH: `Rz(θ) Tz(d) Tx(a) Rx(α)` per joint.
fn ur5e_dh_flange(q: &JointVector) -> Matrix4<f64> {
    let mut pose = Matrix4::identity();
    for i in 0..6 {
        let (st, ct) = libm::sincos(q[i]);
        let (sa, ca) = libm::sincos(UR5E_ALPHA[i]);
        #[rustfmt::skip]
        let link = Matrix4::new(
            ct, -st * ca, st * sa, UR5E_A[i] * ct,
            st, ct * ca, -ct * sa, UR5E_A[i] * st,
            0.0, sa, ca, UR5E_D[i],
            0.0, 0.0, 0.0, 1.0,
        );
        pose *= link;
    }
    pose
}

#[test]
fn ur5e_matches_universal_robots_dh_parameters() {
    let robot = common::ur5e();
    assert_eq!(robot.dof(), 6);
    let mut rng = rng(66);
    let mut worst = 0.0f64;
    for _ in 0..1000 {
        let q = random_q(&mut rng, &robot);
        assert_eq!(q[6], 0.0, "the absent seventh joint stays zero");
        let flange = ur5e_dh_flange(&q);
        let rotation: Matrix3<f64> = flange.fixed_view::<3, 3>(0, 0).into_owned();
        let axis = rotation.column(2).into_owned();
        let tip = flange.fixed_view::<3, 1>(0, 3).into_owned() + axis * PEN_FROM_FLANGE;
        let kin = robot.forward(&q);
        worst = worst
            .max((kin.tcp() - tip).norm())
            .max((kin.tool_axis() - axis).norm());
    }
    assert!(worst < 1e-12, "worst deviation from the DH model {worst:e}");
}
