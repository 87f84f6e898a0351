//! The hybrid executor of extreme straight-line motion (Sec. 4.3, Eq. 8): a learned null-space
//! policy acts in the interior of the joint range and the classical controller in the boundary
//! shell, with a hysteresis switch (`τ_enter ≥ τ_exit`) against chattering. An episode whose seed
//! already lies in the shell starts under the classical controller.
//!
//! ```
//! use emg_hybrid::{HysteresisSwitch, Regime, SwitchConfig};
//! let mut switch = HysteresisSwitch::new(SwitchConfig { tau_enter: 0.98, tau_exit: 0.94 })?;
//! assert_eq!(switch.start(0.5), Regime::Learned);
//! assert_eq!(switch.update(0.99), Regime::Classical); // entered the shell
//! assert_eq!(switch.update(0.96), Regime::Classical); // inside the band: no chatter
//! assert_eq!(switch.update(0.93), Regime::Learned); // left the band
//! assert_eq!(switch.switches(), 2);
//! # Ok::<(), emg_hybrid::SwitchConfigError>(())
//! ```

mod boundary;
mod controller;
mod switch;

pub use boundary::BoundaryMeasure;
pub use controller::{HybridController, count_switches};
pub use switch::{HysteresisSwitch, Regime, SwitchConfig, SwitchConfigError};
