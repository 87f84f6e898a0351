//! Why a drawing cannot be read; each message names what is wrong.

/// Why an SVG text cannot be read as strokes.
#[derive(Debug, thiserror::Error)]
pub enum SvgError {
    /// The text is not SVG (not XML, another root element, or an SVG usvg refuses).
    #[error("the text is not SVG: {reason}")]
    NotSvg {
        /// The XML reader's or usvg's message.
        reason: String,
    },
    /// Nothing drawable is long enough.
    #[error(
        "the drawing holds no stroke: no path, line, polyline, polygon, rect, circle or ellipse \
         with a length of at least {min_stroke_m} m ({dropped} shorter dropped; text and images \
         are not drawn)"
    )]
    Empty {
        /// The shortest stroke kept (m).
        min_stroke_m: f64,
        /// How many shorter strokes were dropped.
        dropped: usize,
    },
    /// `width_m` cannot scale a drawing of no width.
    #[error(
        "the drawing has no width (its bounding box is {height} units high and 0 wide): \
         'width_m' cannot scale it; give 'scale_m_per_unit'"
    )]
    ZeroWidth {
        /// The drawing's height (its units).
        height: f64,
    },
    /// A placement field is unusable.
    #[error("placement field '{field}' {problem}")]
    Placement {
        /// The field, e.g. `x_axis`.
        field: &'static str,
        /// What is wrong.
        problem: String,
    },
    /// An option is unusable.
    #[error("SVG option '{field}' {problem}")]
    Options {
        /// The option, e.g. `curve_tolerance_m`.
        field: &'static str,
        /// What is wrong.
        problem: String,
    },
    /// A stroke did not make a valid path (the placement put it where the path format cannot
    /// hold it, e.g. at absurd coordinates).
    #[error("stroke {index} (element '{element}') is not a valid path: {error}")]
    Stroke {
        /// The stroke's index among the subpaths read.
        index: usize,
        /// The `id` of the element that drew it (empty when none).
        element: String,
        /// The path format's objection.
        error: emg_control::PathError,
    },
}

/// Why an SVG file cannot be read as strokes; names the file.
#[derive(Debug, thiserror::Error)]
pub enum SvgFileError {
    /// The file cannot be read.
    #[error("cannot read SVG file {path}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The file's contents cannot be read as strokes.
    #[error("SVG file {path}: {error}")]
    Svg {
        /// The file.
        path: String,
        /// What is wrong with its contents.
        error: SvgError,
    },
}
