//! Drawings no one would draw on purpose but every exporter writes sometimes: cusps, zero-length
//! and backtracking segments, coincident points, tiny and huge coordinates, paths of a thousand
//! vertices, generated from a seed and planned by `emg job` as a user runs it. None may panic,
//! and every program written passes `emg check`.

mod common;

use common::{emg, temp_dir, text};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// One drawing's `<path>` data: a mix of the hostile pieces, `scale` units per step.
fn hostile_path(rng: &mut ChaCha8Rng, scale: f64) -> String {
    let mut d = format!(
        "M{:.6},{:.6}",
        rng.random_range(0.0..20.0) * scale,
        rng.random_range(0.0..20.0) * scale
    );
    for _ in 0..rng.random_range(3..12) {
        let (dx, dy) = (
            rng.random_range(-4.0..4.0) * scale,
            rng.random_range(-4.0..4.0) * scale,
        );
        d += &match rng.random_range(0..7) {
            // A cusp: the curve's tangent reverses where it starts.
            0 => format!(" c0,0 {:.6},{:.6} {:.6},{:.6}", -dx, -dy, dx, dy),
            // A zero-length segment, then a coincident point.
            1 => format!(" l0,0 L{0:.6},{1:.6} l0,0", dx.abs(), dy.abs()),
            // Out and back over itself.
            2 => format!(" l{dx:.6},{dy:.6} l{:.6},{:.6}", -dx, -dy),
            // A reversal by a hair less than a half turn.
            3 => format!(" l{dx:.6},{dy:.6} l{:.6},{:.6}", -dx, -dy + 0.05 * scale),
            // An arc of a full half-turn and a degenerate one.
            4 => format!(
                " a{0:.6},{0:.6} 0 0 1 {dx:.6},{dy:.6} a0,0 0 0 0 {dx:.6},0",
                (dx * dx + dy * dy).sqrt() / 2.0
            ),
            // A jagged run of short segments, as a flattened coastline.
            5 => (0..rng.random_range(200..1000))
                .map(|_| {
                    format!(
                        " l{:.6},{:.6}",
                        rng.random_range(-0.1..0.15) * scale,
                        rng.random_range(-0.1..0.1) * scale
                    )
                })
                .collect(),
            _ => format!(" q{dx:.6},{:.6} {:.6},0", -dy, 2.0 * dx),
        };
    }
    if rng.random_bool(0.5) {
        d += " z";
    }
    d
}

#[test]
fn hostile_drawings_plan_without_a_panic_and_every_program_checks() {
    let dir = temp_dir("hostile");
    let mut rng = ChaCha8Rng::seed_from_u64(20261201);
    // Units per step from a thousandth to ten thousand: the placement scales the drawing to its
    // width, so the geometry is the same and only the numbers' sizes differ.
    for (index, scale) in [1e-3, 1.0, 1e4].into_iter().enumerate() {
        let paths: String = (0..rng.random_range(2..5))
            .map(|_| {
                format!(
                    r#"<path fill="none" stroke="black" d="{}"/>"#,
                    hostile_path(&mut rng, scale)
                )
            })
            .collect();
        let svg = format!(r#"<svg xmlns="http://www.w3.org/2000/svg">{paths}</svg>"#);
        let drawing = dir.path().join(format!("hostile-{index}.svg"));
        std::fs::write(&drawing, &svg).expect("the drawing is written");
        let program = dir.path().join(format!("hostile-{index}.job.json"));
        let planned = emg(&[
            "job",
            drawing.to_str().unwrap(),
            "--width",
            "0.12",
            "--out",
            program.to_str().unwrap(),
        ]);
        let stderr = text(&planned.stderr);
        assert!(
            !stderr.contains("panicked") && planned.status.code() != Some(101),
            "drawing {index} ({svg}) panics: {stderr}"
        );
        if planned.status.success() {
            let checked = emg(&["check", program.to_str().unwrap()]);
            assert!(
                checked.status.success(),
                "drawing {index}: emg check refuses the program: {}",
                text(&checked.stderr)
            );
        } else {
            assert!(
                stderr.contains("error"),
                "drawing {index} fails without saying why: {stderr}"
            );
        }
    }
}
