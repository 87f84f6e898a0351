//! Screenshots of a viewer page in headless Chromium, decoded, and the check that one is not
//! blank.

use std::collections::HashSet;
use std::io::BufReader;
use std::path::Path;

use super::browser::run_browser;

/// The colour the page paints link capsules with, read from the viewer's core script.
pub fn link_colour() -> [u8; 3] {
    script_colour("LINK_COLOUR")
}

/// The `#rrggbb` colour the viewer's scripts define as `const NAME = "#rrggbb"`.
pub fn script_colour(name: &str) -> [u8; 3] {
    let scripts = [
        include_str!("../../src/viewer.js"),
        include_str!("../../src/motion.js"),
        include_str!("../../src/job.js"),
    ];
    let needle = format!("const {name} = \"#");
    let line = scripts
        .iter()
        .flat_map(|script| script.lines())
        .find(|l| l.contains(&needle))
        .unwrap_or_else(|| panic!("the viewer's scripts define {name}"));
    let hex = line.split('#').nth(1).expect("a # colour")[..6].to_owned();
    let channel = |i: usize| u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).expect("hex colour");
    [channel(0), channel(1), channel(2)]
}

/// How many of `pixels` are `colour` (each channel within 8).
pub fn pixels_of(pixels: &[[u8; 3]], colour: [u8; 3]) -> usize {
    pixels
        .iter()
        .filter(|px| (0..3).all(|c| px[c].abs_diff(colour[c]) <= 8))
        .count()
}

/// Renders `page` to a PNG screenshot and returns it as RGB pixels `(width, height, rgb)`.
pub fn screenshot(browser: &Path, dir: &Path, page: &str) -> (u32, u32, Vec<[u8; 3]>) {
    let png_path = dir.join("screenshot.png");
    let _ = std::fs::remove_file(&png_path);
    let run = run_browser(
        browser,
        dir,
        page,
        &[format!("--screenshot={}", png_path.display())],
    );
    let file = std::fs::File::open(&png_path).unwrap_or_else(|e| {
        panic!(
            "no screenshot at {}: {e}\nbrowser stderr:\n{}",
            png_path.display(),
            run.stderr
        )
    });
    let mut decoder = png::Decoder::new(BufReader::new(file));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().expect("a PNG screenshot");
    let mut buffer = vec![0; reader.output_buffer_size().expect("a sane PNG size")];
    let info = reader
        .next_frame(&mut buffer)
        .expect("decode the screenshot");
    let channels = info.color_type.samples();
    let pixels = buffer[..info.buffer_size()]
        .chunks_exact(channels)
        .map(|px| match channels {
            1 | 2 => [px[0]; 3],
            _ => [px[0], px[1], px[2]],
        })
        .collect();
    (info.width, info.height, pixels)
}

/// Why a screenshot looks blank: too few distinct colours, or too few pixels in the link colour.
pub fn blank_screenshot_problem(pixels: &[[u8; 3]]) -> Option<String> {
    const MIN_COLOURS: usize = 300;
    const MIN_LINK_PIXELS: usize = 3000;
    let colours = pixels.iter().collect::<HashSet<_>>().len();
    let link = link_colour();
    let link_pixels = pixels_of(pixels, link);
    let mut problems = Vec::new();
    if colours < MIN_COLOURS {
        problems.push(format!(
            "{colours} distinct colours (expected at least {MIN_COLOURS})"
        ));
    }
    if link_pixels < MIN_LINK_PIXELS {
        problems.push(format!(
            "{link_pixels} pixels in the link colour {link:?} (expected at least {MIN_LINK_PIXELS})"
        ));
    }
    (!problems.is_empty()).then(|| problems.join("; "))
}
