//! GPU timestamp queries around each pass (when the adapter has `TIMESTAMP_QUERY`).

use crate::error::{RenderError, Result};

/// Pass names: the frame order is shadow, G-buffer, occlusion, shading, custom, post; the
/// occlusion pass (session 28) comes last here so that the tables' and CSVs' columns before it
/// keep their places.
pub const PASSES: [&str; 6] = ["shadow", "gbuffer", "shading", "custom", "post", "occlusion"];

/// Index of the occlusion pass in [`PASSES`].
pub(crate) const OCCLUSION: usize = 5;

/// GPU time of each pass of the last frame rendered with `timestamps: true`, milliseconds; 0
/// for a pass the frame did not run (the occlusion pass without ambient light).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PassTimings {
    pub ms: [f64; PASSES.len()],
}

impl PassTimings {
    pub fn total_ms(&self) -> f64 {
        self.ms.iter().sum()
    }

    pub fn get(&self, pass: &str) -> Option<f64> {
        PASSES.iter().position(|p| *p == pass).map(|i| self.ms[i])
    }
}

pub(crate) struct Timer {
    queries: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    /// Nanoseconds per tick.
    period: f64,
    pub(crate) pending: bool,
    /// Bit i: pass i ran in the frame being recorded (or last recorded); the others wrote their
    /// timestamps around an empty pass ([`Self::idle`]) and read as 0.
    ran: std::cell::Cell<u32>,
}

const COUNT: u32 = 2 * PASSES.len() as u32;

impl Timer {
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        let queries = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: COUNT,
        });
        let size = COUNT as u64 * 8;
        let resolve = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamp resolve"),
            size,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamp readback"),
            size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        Timer {
            queries,
            resolve,
            readback,
            period: queue.get_timestamp_period() as f64,
            pending: false,
            ran: std::cell::Cell::new(0),
        }
    }

    /// Starts recording a frame's timestamps: no pass has run yet.
    pub fn start_frame(&self) {
        self.ran.set(0);
    }

    pub fn writes(&self, pass: usize) -> wgpu::RenderPassTimestampWrites<'_> {
        self.ran.set(self.ran.get() | 1 << pass);
        wgpu::RenderPassTimestampWrites {
            query_set: &self.queries,
            beginning_of_pass_write_index: Some(2 * pass as u32),
            end_of_pass_write_index: Some(2 * pass as u32 + 1),
        }
    }

    /// Writes pass `pass`'s two timestamps around an empty compute pass, for a frame that does
    /// not run it: every query the frame resolves must be written in it (the copy of the results
    /// waits for each; one never written would never be ready). Its time reads as 0.
    pub fn idle(&self, encoder: &mut wgpu::CommandEncoder, pass: usize) {
        let writes = wgpu::ComputePassTimestampWrites {
            query_set: &self.queries,
            beginning_of_pass_write_index: Some(2 * pass as u32),
            end_of_pass_write_index: Some(2 * pass as u32 + 1),
        };
        encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(PASSES[pass]),
            timestamp_writes: Some(writes),
        });
    }

    /// Only the start of pass `pass`'s time: a pass recorded in two parts starts with this one.
    pub fn begins(&self, pass: usize) -> wgpu::RenderPassTimestampWrites<'_> {
        wgpu::RenderPassTimestampWrites { end_of_pass_write_index: None, ..self.writes(pass) }
    }

    /// Only the end of pass `pass`'s time (the second part of [`Self::begins`]).
    pub fn ends(&self, pass: usize) -> wgpu::RenderPassTimestampWrites<'_> {
        wgpu::RenderPassTimestampWrites { beginning_of_pass_write_index: None, ..self.writes(pass) }
    }

    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.queries, 0..COUNT, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, COUNT as u64 * 8);
    }

    /// Waits for the GPU and reads the timestamps of the last resolved frame.
    pub fn read(&mut self, device: &wgpu::Device) -> Result<PassTimings> {
        let ticks: Vec<u64> =
            crate::readback::map_buffer(device, &self.readback, |b| bytemuck::cast_slice(b).to_vec())?;
        self.pending = false;
        let mut t = PassTimings::default();
        for (i, ms) in t.ms.iter_mut().enumerate() {
            if self.ran.get() & 1 << i == 0 {
                continue;
            }
            let (a, b) = (ticks[2 * i], ticks[2 * i + 1]);
            if b < a {
                return Err(RenderError::Readback(format!("timestamps of pass {} go backwards", PASSES[i])));
            }
            *ms = (b - a) as f64 * self.period * 1e-6;
        }
        Ok(t)
    }
}
