//! The placement screen against what the job draws: near the edge of the FR3's reach the
//! screened score of every place of a small grid is at least the share the job planned there
//! draws; and places are planned until no refined place left unplanned scores above what the
//! chosen one draws.

mod common;

use emg_io::Placement as SvgPlacement;
use emg_job::{Moving, PlaceSettings, Region, Score, Unwatched, place_job};
use emg_planner::PlanRequest;

/// The signature 0.4 m wide near the edge of the FR3's reach placed over a 3 × 3 grid of shifts
/// `x_m` along x (and 0 to 0.2 m along y) with `certify` places planned at least, each stroke
/// planned in `max_parts` parts at most.
fn placed(x_m: [f64; 2], certify: usize, max_parts: usize) -> (emg_job::Placement, f64) {
    let (planner, timing, _, file) = common::setup("fr3");
    let robot = planner.robot();
    let svg = common::workspace().join("crates/io/tests/data/icons/signature.svg");
    let placement = SvgPlacement {
        origin_m: [0.6, 0.5, 0.05],
        width_m: Some(0.4),
        ..SvgPlacement::default()
    };
    let mut job = common::drawing(robot, &svg, &placement);
    job.settings.max_parts = max_parts;
    let region = Region {
        moving: Moving::Part,
        x_m,
        y_m: [0.0, 0.2],
        z_m: [0.0, 0.0],
        rotation_deg: [0.0, 0.0],
    };
    let settings = PlaceSettings {
        positions: 3,
        heights: 1,
        rotations: 1,
        refine: 9,
        certify,
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
    (found, slack)
}

#[test]
fn the_screened_score_bounds_the_share_drawn_at_every_place() {
    // Every screened place refined, and every refined place planned.
    let default = emg_job::JobSettings::default().max_parts;
    let (found, slack) = placed([-0.1, 0.2], 9 + 8, default);
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

#[test]
fn places_are_planned_until_none_left_scores_above_the_chosen_one() {
    // Farther out, each stroke in one part each way, where the first place planned draws
    // less than others score.
    let (found, _) = placed([0.3, 0.45], 1, 1);
    let chosen = &found.certified[0];
    let drawn = chosen.drawn_m / chosen.total_m;
    assert!(
        found.certified.len() > 1,
        "only the first place was planned: drew {drawn:.3}; refined {:?}",
        found
            .refined
            .iter()
            .map(|r| (r.place.x_m, r.place.y_m, r.score))
            .collect::<Vec<_>>()
    );
    for refined in &found.refined {
        let planned = found
            .certified
            .iter()
            .any(|c| c.scored.place == refined.place);
        assert!(
            planned || refined.score <= drawn + emg_job::SAME_SCORE,
            "{:?} scores {:.3} above the chosen place's {drawn:.3} and was not planned",
            refined.place,
            refined.score
        );
    }
}
