//! Subcommands, one file each.

pub mod bench;
pub mod demo;
pub mod diff;
pub mod eval;
pub mod lut;
pub mod render;
pub mod truth;
pub mod upsample;
pub mod view;
