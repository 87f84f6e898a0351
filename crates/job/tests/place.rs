//! The placement screen against what the job draws: near the edge of the FR3's reach, where
//! the signature's long stroke drawn from one end draws a tenth of what it draws from the
//! other, the screened score of every place of a small grid is at least the share the job
//! planned there draws.

mod common;

use emg_io::Placement as SvgPlacement;
use emg_job::{Moving, PlaceSettings, Region, Score, Unwatched, place_job};
use emg_planner::PlanRequest;

#[test]
fn the_screened_score_bounds_the_share_drawn_at_every_place() {
    let (planner, timing, _, file) = common::setup("fr3");
    let robot = planner.robot();
    let svg = common::workspace().join("crates/io/tests/data/icons/signature.svg");
    let placement = SvgPlacement {
        origin_m: [0.6, 0.5, 0.05],
        width_m: Some(0.4),
        ..SvgPlacement::default()
    };
    let job = common::drawing(robot, &svg, &placement);
    let region = Region {
        moving: Moving::Part,
        x_m: [-0.1, 0.2],
        y_m: [0.0, 0.2],
        z_m: [0.0, 0.0],
        rotation_deg: [0.0, 0.0],
    };
    // Every screened place refined and certified.
    let settings = PlaceSettings {
        positions: 3,
        heights: 1,
        rotations: 1,
        refine: 9,
        certify: 9 + 8,
        ..PlaceSettings::default()
    };
    let found = place_job(
        &planner,
        &PlanRequest::default(),
        &job,
        &timing,
        &file.display().to_string(),
        &region,
        &settings,
        Score::Bound,
        &Unwatched,
    )
    .expect("places found");
    // The bound is found on a scan of grid points: a motion may go on up to one step past the
    // last of them on each stroke.
    let slack = job.strokes.len() as f64 * planner.config().reach.grid_m;
    let mut partial = 0;
    for certified in &found.certified {
        let drawn = certified.drawn_m / certified.total_m;
        assert!(
            certified.scored.score >= drawn - slack / certified.total_m,
            "{:?}: screened {:.3}, drawn {drawn:.3}",
            certified.scored.place,
            certified.scored.score
        );
        partial += usize::from(drawn < 0.99);
    }
    assert!(found.certified.len() >= 9);
    assert!(partial >= 2, "{partial} places draw part of the job");
}
