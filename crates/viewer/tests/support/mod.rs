//! Helpers shared by the viewer's integration tests.
#![allow(dead_code)]

pub mod browser;
pub mod job;
pub mod screenshot;
