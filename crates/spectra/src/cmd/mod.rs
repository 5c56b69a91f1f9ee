//! Subcommands, one file each.

pub mod diff;
pub mod truth;
