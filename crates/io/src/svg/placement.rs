//! Where a drawing lands on the work surface, and how large.

use emg_kinematics::Vec3;
use serde::{Deserialize, Serialize};

use super::bezier::V2;
use super::bounds::DrawingBounds;
use super::error::SvgError;

/// Metres per SVG unit for a drawing at its own physical size: the drawing's units are CSS
/// pixels, 96 to the inch (`scale_m_per_unit: SVG_PX_M` draws a `width="100mm"` drawing
/// 0.1 m wide).
pub const SVG_PX_M: f64 = 0.0254 / 96.0;

/// Where a drawing goes on the work surface, and how large (JSON: `origin_m`, `normal`,
/// `x_axis`, and one of `width_m` and `scale_m_per_unit`).
///
/// The centre of the drawing's bounding box goes to `origin_m`; the drawing lies in the plane
/// through it normal to `normal`. The drawing's x (rightwards) runs along `x_axis` (projected
/// into that plane and normalised) and its y (downwards, as SVG draws it) along
/// `normal × x_axis`. Since `x_axis × (normal × x_axis) = normal`, the drawing reads right —
/// turned, never mirrored — for an eye looking along `normal`: from the tool's side of the
/// surface, with the tool axis, as a pen sees the sheet it draws on.
///
/// [`Placement::default`] draws pen down (`normal` `(0, 0, −1)`) on a horizontal plate in
/// front of the arm, 0.2 m wide, centred at `(0.45, 0, 0.25)` — the middle of the demo line
/// of docs/cli.md (`--p0 0.45,-0.2,0.25 --d 0,1,0 --n 0,0,-1`) — with the drawing's x along
/// `−y` and its y along `−x` (towards the arm's base): seen from above, its top faces away
/// from the arm.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Placement {
    /// Where the centre of the drawing's bounding box goes (m, base frame).
    pub origin_m: [f64; 3],
    /// The surface normal `n`: the tool axis direction, as in a path (normalised on use).
    pub normal: [f64; 3],
    /// The direction of the drawing's x on the surface (projected into the plane normal to
    /// `normal` and normalised; it must not be parallel to `normal`).
    pub x_axis: [f64; 3],
    /// The width (m) the drawing's bounding box gets; give this or `scale_m_per_unit`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width_m: Option<f64>,
    /// Metres per unit of the drawing (its CSS pixels, [`SVG_PX_M`] for its physical size);
    /// give this or `width_m`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale_m_per_unit: Option<f64>,
}

impl Default for Placement {
    fn default() -> Self {
        Self {
            origin_m: [0.45, 0.0, 0.25],
            normal: [0.0, 0.0, -1.0],
            x_axis: [0.0, -1.0, 0.0],
            width_m: Some(0.2),
            scale_m_per_unit: None,
        }
    }
}

/// A validated placement: the drawing plane's origin and unit axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Frame {
    /// Where the bounding box's centre goes.
    pub origin: Vec3,
    /// The unit surface normal.
    pub normal: Vec3,
    /// The drawing's x on the surface (unit).
    pub x: Vec3,
    /// The drawing's y on the surface: `normal × x`.
    pub y: Vec3,
}

impl Frame {
    /// The point of the surface at plane coordinates `p` (m along `x` and `y` from the
    /// origin).
    pub fn point(&self, p: V2) -> [f64; 3] {
        (self.origin + self.x * p.x + self.y * p.y).into()
    }
}

fn refused(field: &'static str, problem: String) -> SvgError {
    SvgError::Placement { field, problem }
}

/// A finite vector of a placement field.
fn finite(field: &'static str, v: [f64; 3]) -> Result<Vec3, SvgError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(Vec3::from(v))
    } else {
        Err(refused(field, format!("is not finite: {v:?}")))
    }
}

/// A finite direction of a placement field, normalised.
fn direction(field: &'static str, v: [f64; 3]) -> Result<Vec3, SvgError> {
    let v = finite(field, v)?;
    if v.norm() < 1e-12 {
        return Err(refused(
            field,
            "is a zero vector; it must be a direction".into(),
        ));
    }
    Ok(v.normalize())
}

impl Placement {
    /// The plane the drawing goes on; refused when a field is not finite, a direction is
    /// zero or `x_axis` is parallel to `normal`.
    pub(crate) fn frame(&self) -> Result<Frame, SvgError> {
        let origin = finite("origin_m", self.origin_m)?;
        let normal = direction("normal", self.normal)?;
        let x = direction("x_axis", self.x_axis)?;
        let along = x - normal * x.dot(&normal);
        // Within a millionth of a radian of the normal there is no direction left.
        if along.norm() < 1e-6 {
            return Err(refused(
                "x_axis",
                format!(
                    "{:?} is parallel to 'normal' {:?}: it must have a direction along the \
                     surface",
                    self.x_axis, self.normal
                ),
            ));
        }
        let x = along.normalize();
        Ok(Frame {
            origin,
            normal,
            x,
            y: normal.cross(&x),
        })
    }

    /// Metres per drawing unit for a drawing of `bounds`: from `width_m` or
    /// `scale_m_per_unit`, exactly one of which must be given, finite and positive.
    pub(crate) fn scale(&self, bounds: &DrawingBounds) -> Result<f64, SvgError> {
        let positive = |field: &'static str, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(value)
            } else {
                Err(refused(
                    field,
                    format!("is {value}; it must be a positive length"),
                ))
            }
        };
        match (self.width_m, self.scale_m_per_unit) {
            (Some(width_m), None) => {
                let width_m = positive("width_m", width_m)?;
                let width = bounds.width();
                // Below single precision's resolution of the drawing's coordinates a width is
                // no width.
                let magnitude = bounds
                    .min
                    .iter()
                    .chain(&bounds.max)
                    .fold(0.0f64, |m, v| m.max(v.abs()));
                if width <= 1e-7 * magnitude || width <= 0.0 {
                    return Err(SvgError::ZeroWidth {
                        height: bounds.height(),
                    });
                }
                Ok(width_m / width)
            }
            (None, Some(scale)) => positive("scale_m_per_unit", scale),
            (Some(_), Some(_)) => Err(refused(
                "width_m",
                "is given with 'scale_m_per_unit'; give one of them".into(),
            )),
            (None, None) => Err(refused(
                "width_m",
                "is missing: give 'width_m' or 'scale_m_per_unit'".into(),
            )),
        }
    }
}
