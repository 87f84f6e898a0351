//! The clearance floors of the shipped arms: each holds at random configurations within the
//! limits, lies within the search's tolerance of a clearance it measured, and on the FR3 the
//! segment pairs one and two joints from the hand (which every step used to measure) get one.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::clearance_floor::FLOOR_TOLERANCE_M;
use crate::{JointVector, Robot};

fn shipped(file: &str, base: &str, tip: &str) -> Robot {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/robots")
        .join(file);
    Robot::from_urdf_file(path, base, tip).expect("shipped robot file loads")
}

fn fr3() -> Robot {
    shipped("fr3_pen.urdf", "link0", "pen_tip")
}

fn iiwa14() -> Robot {
    shipped("iiwa14_pen.urdf", "iiwa_link_0", "pen_tip")
}

#[test]
fn every_floor_holds_within_the_limits_and_is_tight() {
    for robot in [fr3(), iiwa14()] {
        let mut rng = ChaCha8Rng::seed_from_u64(61);
        let limits = robot.limits();
        let configurations: Vec<JointVector> = (0..5000)
            .map(|_| {
                JointVector::from_fn(|i, _| rng.random_range(limits.lower[i]..limits.upper[i]))
            })
            .collect();
        let mut floored = 0;
        for group in &robot.broad_phase.groups {
            let floor = group.floor;
            if floor.floor == f64::NEG_INFINITY {
                continue;
            }
            floored += 1;
            assert!(floor.floor <= floor.smallest_measured);
            assert!(
                floor.smallest_measured - floor.floor <= FLOOR_TOLERANCE_M,
                "{:?}: the search stopped short of its tolerance: {floor:?}",
                group.segments
            );
            let nearest = configurations
                .iter()
                .map(|q| {
                    let kin = robot.forward(q);
                    group
                        .pairs
                        .iter()
                        .map(|&index| robot.pair_clearance(&kin, robot.pairs[index]))
                        .fold(f64::INFINITY, f64::min)
                })
                .fold(f64::INFINITY, f64::min);
            println!(
                "{}: segments {:?}, floor {:.4} m, nearest of 5000 random configurations {nearest:.4} m",
                robot.name(),
                group.segments,
                floor.floor
            );
            assert!(nearest >= floor.floor, "{:?}", group.segments);
        }
        assert!(
            floored > 0,
            "{} has segment pairs one or two joints apart",
            robot.name()
        );
    }
}

#[test]
fn the_fr3_hand_is_certified_clear_of_links_five_and_six() {
    let robot = fr3();
    for segments in [(5, 7), (6, 7)] {
        let group = robot
            .broad_phase
            .groups
            .iter()
            .find(|group| group.segments == segments)
            .expect("the FR3 checks the hand against links 5 and 6");
        assert!(group.floor.floor > 0.04, "{segments:?}: {:?}", group.floor);
    }
}
