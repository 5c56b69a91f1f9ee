//! Reflection test: every WGSL struct the CPU writes and every constant both sides size things
//! with, read from the WGSL as naga (wgpu's own front end) parses it and compared with the Rust
//! `#[repr(C)]` mirror or constant. Replaces the "must match" comments: a field added on one
//! side only, a reordered field or a changed constant fails here, before any GPU test runs.

use crate::passes::custom::{CustomShader, CustomUniforms, MEDIUM_COMMON};
use crate::passes::{rgb_medium, shadow, underwater};
use crate::shader;
use naga::{Expression, Literal, Module, TypeInner};

/// The module `parts` assemble to, as the passes assemble it ([`shader::compile`]).
fn parse(parts: &[&str]) -> Module {
    let source = parts.join("\n");
    naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)))
}

/// A struct's size and its members' (offset, size), in bytes; padding members (named `_…`) are
/// left out, as their split differs (`_pad: [u32; 3]` against three `u32`) and the struct's
/// size covers them.
#[derive(Debug, PartialEq)]
struct Layout {
    size: usize,
    members: Vec<(usize, usize)>,
}

/// The layout of WGSL struct `name` in `module`, with its member names for messages.
fn wgsl_layout(module: &Module, name: &str) -> (Layout, Vec<String>) {
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).expect("layouts of a parsed module");
    let (_, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no WGSL struct {name}"));
    let TypeInner::Struct { members, span } = &ty.inner else { panic!("{name} is not a struct") };
    let layout = Layout {
        size: *span as usize,
        members: members
            .iter()
            .filter(|m| !m.name.as_deref().unwrap_or_default().starts_with('_'))
            .map(|m| (m.offset as usize, layouter[m.ty].size as usize))
            .collect(),
    };
    (layout, members.iter().map(|m| m.name.clone().unwrap_or_default()).collect())
}

/// The size of the field `f` selects (for [`rust_layout!`]).
fn field_size<T, F>(_: fn(&T) -> &F) -> usize {
    std::mem::size_of::<F>()
}

/// The [`Layout`] of a Rust struct from its fields in declaration order.
macro_rules! rust_layout {
    ($t:ty { $($f:ident),* $(,)? }) => {
        Layout {
            size: std::mem::size_of::<$t>(),
            members: [$((stringify!($f), std::mem::offset_of!($t, $f), field_size(|s: &$t| &s.$f))),*]
                .into_iter()
                .filter(|(name, _, _)| !name.starts_with('_'))
                .map(|(_, offset, size)| (offset, size))
                .collect(),
        }
    };
}

/// Asserts that WGSL struct `name` in `module` is byte for byte `rust`.
fn check(module: &Module, name: &str, rust: Layout) {
    let (wgsl, names) = wgsl_layout(module, name);
    assert_eq!(wgsl, rust, "WGSL {name} (members {names:?}) vs its Rust mirror: (offset, size) differ");
}

/// The value of the `u32` constant `name`.
fn const_u32(module: &Module, name: &str) -> u32 {
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no WGSL constant {name}"));
    match module.global_expressions[c.init] {
        Expression::Literal(Literal::U32(v)) => v,
        ref e => panic!("WGSL constant {name} is not a u32 literal: {e:?}"),
    }
}

fn const_f32(module: &Module, name: &str) -> f32 {
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no WGSL constant {name}"));
    match module.global_expressions[c.init] {
        Expression::Literal(Literal::F32(v)) => v,
        ref e => panic!("WGSL constant {name} is not an f32 literal: {e:?}"),
    }
}

fn shading_module(custom: &CustomShader) -> Module {
    let hooks = custom.assembled();
    parse(&crate::passes::shading::sources(&hooks))
}

#[test]
fn uniform_and_storage_structs_match_their_rust_mirrors() {
    use crate::env_gpu::EnvUniforms;
    use crate::scene_gpu::{GpuLight, MaterialUniforms};
    use crate::spectral_data::WavelengthGroup;
    use crate::uniforms::FrameUniforms;

    let shading = shading_module(&CustomShader::default());
    check(
        &shading,
        "FrameUniforms",
        rust_layout!(FrameUniforms {
            view_proj,
            inv_view_proj,
            camera_pos,
            xyz_to_rgb,
            viewport,
            mode,
            n_groups,
            n_lights,
            exposure,
            tonemap,
            table_res,
            flags,
            frame_index,
            lod_bias,
            node_spacing,
            _pad,
        }),
    );
    check(
        &shading,
        "ShadowUniforms",
        rust_layout!(shadow::ShadowUniforms { view_proj, bias, layer_of_light }),
    );
    check(&shading, "EnvUniforms", rust_layout!(EnvUniforms { totals, params, flags }));
    check(
        &shading,
        "MaterialSpectrum",
        rust_layout!(crate::material_spectra::MaterialSpectrum {
            base,
            emission,
            emission_xyz,
            film,
            refraction,
            absorption,
            specular,
            sheen
        }),
    );
    check(
        &shading,
        "WavelengthGroup",
        rust_layout!(WavelengthGroup {
            lambda,
            white_x,
            white_y,
            white_z,
            band_r,
            band_g,
            band_b,
            _pad,
            band_white_r,
            band_white_g,
            band_white_b
        }),
    );
    check(&shading, "GpuLight", rust_layout!(GpuLight { pos_kind, dir_range, cone, rgb, xyz, extra }));
    check(&shading, "CustomUniforms", rust_layout!(CustomUniforms { params, n_spectra, _pad }));

    let gbuffer =
        parse(&[shader::COMMON, shader::HASH, shader::MATERIAL, include_str!("passes/gbuffer.wgsl")]);
    check(
        &gbuffer,
        "MaterialUniforms",
        rust_layout!(MaterialUniforms {
            base_color,
            emissive,
            params,
            alpha,
            uv,
            slot,
            film,
            transmission,
            coat,
            specular,
            sheen,
            anisotropy,
            diffuse_transmission
        }),
    );
    let shadow_pass = parse(&[shader::HASH, shader::MATERIAL, include_str!("passes/shadow.wgsl")]);
    check(&shadow_pass, "ShadowLayer", rust_layout!(shadow::LayerUniforms { view_proj, params }));
}

#[test]
fn shared_constants_match_the_rust_constants() {
    use crate::scene_gpu::MAX_LIGHTS;
    let shading = shading_module(&CustomShader::default());
    assert_eq!(const_u32(&shading, "MAX_LIGHTS") as usize, MAX_LIGHTS);
    assert_eq!(const_u32(&shading, "MAX_SHADOWS") as usize, shadow::MAX_SHADOWS);
    assert_eq!(const_u32(&shading, "NO_SHADOW"), shadow::NO_SHADOW);
    assert_eq!(const_u32(&shading, "AXIS_INDEX") as usize, crate::coeff_table::AXIS_INDEX);
    assert_eq!(const_u32(&shading, "LTC_SIZE") as usize, crate::ltc::SIZE);
    assert_eq!(const_u32(&shading, "SCREEN_GROUP"), crate::passes::SCREEN_GROUP);
    let tan = (shadow::EMITTER_FOV / 2.0).tan();
    assert!((const_f32(&shading, "EMITTER_TAN_HALF_FOV") - tan).abs() < 1e-6 * tan);

    let hooks = format!("{MEDIUM_COMMON}\n{}", underwater::HOOKS);
    let water = shading_module(&CustomShader::new(hooks));
    assert_eq!(const_u32(&water, "UW_MAX_LIGHTS") as usize, MAX_LIGHTS);
    assert_eq!(const_u32(&water, "UW_SS_LIGHTS") as usize, underwater::SS_LIGHTS);
    assert_eq!(const_u32(&water, "UW_MAX_STEPS"), underwater::MAX_STEPS);
    assert_eq!(const_u32(&water, "UW_MAX_PIECES") as usize, scene::water::light_field::N_DEPTH + 2);

    let hooks = format!("{MEDIUM_COMMON}\n{}", rgb_medium::HOOKS);
    let medium = shading_module(&CustomShader::new(hooks));
    assert_eq!(const_u32(&medium, "RM_MAX_LIGHTS") as usize, MAX_LIGHTS);
    assert_eq!(const_u32(&medium, "RM_SS_LIGHTS") as usize, rgb_medium::SS_LIGHTS);
    assert_eq!(const_u32(&medium, "RM_MAX_STEPS"), rgb_medium::MAX_STEPS);
}

#[test]
fn water_parameters_and_constants_match_the_wgsl() {
    use color::water::WaterType;
    let medium =
        scene::water::WaterMedium::new(WaterType::parse("II").unwrap(), 7.5, glam::Vec3::Y, 0.5).unwrap();
    // The paper's model: no light-field table to solve, and every override the shader sets
    // whatever the options (the table's depth range and the floor's extent only come with a table).
    let water = underwater::shader_with(&medium, &underwater::Options::paper()).unwrap();
    let module = shading_module(&water);
    use underwater::WaterParams;
    check(
        &module,
        "UwParams",
        rust_layout!(WaterParams {
            depth,
            scale,
            steps,
            phase_g,
            c_rgb,
            c_min,
            kd_rgb,
            gershun,
            b_rgb,
            split_beams
        }),
    );
    assert_eq!(std::mem::size_of::<WaterParams>(), std::mem::size_of_val(&water.params));

    // Every constant the Rust side sets is an override of the WGSL (wgpu refuses unknown names
    // at pipeline creation) and every override without a default is set.
    let overrides: Vec<(&str, bool)> = module
        .overrides
        .iter()
        .filter_map(|(_, o)| o.name.as_deref().map(|n| (n, o.init.is_some())))
        .filter(|(n, _)| n.starts_with("UW_"))
        .collect();
    let set: Vec<&str> = water.constants.iter().map(|(n, _)| n.as_str()).collect();
    for name in &set {
        assert!(
            overrides.iter().any(|(n, _)| n == name),
            "{name} is set but underwater.wgsl has no such override"
        );
    }
    for (name, has_default) in &overrides {
        assert!(*has_default || set.contains(name), "override {name} has no default and is not set");
    }
    assert!(set.len() >= 14, "{set:?}");
}
