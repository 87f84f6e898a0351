//! Pieces shared by the learned crates (`emg-policy`, `emg-diffusion`):
//!
//! - [`Backend`]: the Burn CPU backend training runs on, chosen at run time by the tensor device;
//! - [`container`]: the versioned binary container their weights files use — 8 magic bytes, a
//!   `u32` format version, a `u32` header length, a JSON header, a `u64` value count, then the
//!   values as little-endian `f32` — with strict truncation and trailing-byte checks (the
//!   weights files are written with `emg_io::write_atomically`), and [`container::read_file`]
//!   with its [`container::FileAccessError`], the one way both read their files;
//! - [`RobotStamp`]: the robot a weights file was trained for (name and chain fingerprint), and
//!   [`check_stamp`], which refuses a file trained for another arm;
//! - [`StandardNormal`]: normal samples with the same bits on every machine (the noise of both
//!   models' training and of the seeder's sampling);
//! - [`checkpoint`]: checkpoint directories (a model, its optimizer and the JSON run state)
//!   written into a staging sibling and swapped in whole.
//!
//! ```
//! use emg_learning::container::{decode, encode};
//!
//! let bytes = encode(b"EXAMPLE!", 3, &vec![2_usize, 2], &[1.0, -2.0, 0.5, 4.0]);
//! let (header, values): (Vec<usize>, Vec<f32>) = decode(&bytes, b"EXAMPLE!", 3).unwrap();
//! assert_eq!(header, [2, 2]);
//! assert_eq!(values, [1.0, -2.0, 0.5, 4.0]);
//! ```

mod backend;
#[cfg(feature = "train")]
pub mod checkpoint;
pub mod container;
mod normal;
mod stamp;

pub use backend::Backend;
pub use container::ContainerError;
pub use normal::StandardNormal;
pub use stamp::{RobotStamp, StampError, check_stamp};
