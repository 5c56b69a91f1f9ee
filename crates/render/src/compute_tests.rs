//! Running a WGSL function on the GPU for tests that compare it with its Rust twin.

/// Compiles `src` (entry point `main`, workgroup size 64), binds what `bind` returns for the
/// pipeline and the output buffer (`out_bytes` long, storage), dispatches `n` invocations and
/// reads the output back.
pub(crate) fn run(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    src: String,
    n: usize,
    out_bytes: u64,
    bind: impl FnOnce(&wgpu::ComputePipeline, &wgpu::Buffer) -> Vec<wgpu::BindGroup>,
) -> Vec<u8> {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("compute test"),
        source: wgpu::ShaderSource::Wgsl(src.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("compute test"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: out_bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: out_bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let groups = bind(&pipeline, &output);
    let mut enc = device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        for (i, g) in groups.iter().enumerate() {
            pass.set_bind_group(i as u32, g, &[]);
        }
        pass.dispatch_workgroups(n.div_ceil(64) as u32, 1, 1);
    }
    enc.copy_buffer_to_buffer(&output, 0, &staging, 0, out_bytes);
    queue.submit([enc.finish()]);
    crate::readback::map_buffer(device, &staging, |b| b.to_vec()).unwrap()
}

/// The common case of [`run`]: `src` reads `data` (storage, group 0 binding 0) and writes the
/// output (binding 1).
pub(crate) fn run_on(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    src: String,
    n: usize,
    out_bytes: u64,
    data: &[u8],
) -> Vec<u8> {
    use wgpu::util::DeviceExt;
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: data,
        usage: wgpu::BufferUsages::STORAGE,
    });
    run(device, queue, src, n, out_bytes, |p, output| {
        vec![device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &p.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: input.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: output.as_entire_binding() },
            ],
        })]
    })
}
