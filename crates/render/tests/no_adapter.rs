//! Without an adapter for the requested backend, the renderer reports what to install instead
//! of panicking. (Its own test binary: it sets WGPU_BACKEND for the whole process.)

#[test]
fn missing_backend_gives_install_hint() {
    // Metal does not exist on Linux, so no adapter can match: the same path as a machine
    // without any Vulkan/GL driver. (On macOS, pick a backend that is absent there.)
    let absent = if cfg!(target_os = "macos") { "dx12" } else { "metal" };
    // SAFETY: this test binary has a single test, so no other thread reads the environment.
    unsafe { std::env::set_var("WGPU_BACKEND", absent) };
    let err = match render::Gpu::headless() {
        Ok(gpu) => panic!("expected no adapter with WGPU_BACKEND={absent}, got {}", gpu.describe()),
        Err(e) => e.to_string(),
    };
    assert!(err.contains("apt-get install mesa-vulkan-drivers libvulkan1"), "{err}");
    assert!(err.starts_with("no GPU adapter found"), "{err}");
}
