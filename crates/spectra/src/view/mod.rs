//! `spectra view`: the interactive window (winit + egui over the wgpu renderer).
//!
//! `camera` (orbit/fly maths) and `controls` (settings edits, shortcuts) hold no GPU state
//! and are unit-tested; `app` wires them to winit, the surface and the renderer; `blit`
//! copies the renderer's output onto the swap chain; `water` is the underwater panel, `environment` the environment picker.

pub mod app;
mod blit;
pub mod camera;
pub mod controls;
pub mod environment;
pub mod water;
