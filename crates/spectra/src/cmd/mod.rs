//! Subcommands, one file each.

pub mod diff;
pub mod render;
pub mod truth;
