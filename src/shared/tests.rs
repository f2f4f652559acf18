//! Every `repr(C)` struct of `shared` against naga's layout of its WGSL twin.
use std::mem::{offset_of, size_of};

use super::*;
use crate::shader::assert_wgsl_layout;

#[test]
fn gpu_structs_match_their_wgsl_twins() {
    assert_wgsl_layout(
        "triangles",
        "BvhTriangle",
        size_of::<GpuTriangle>(),
        &[
            ("v0", offset_of!(GpuTriangle, v0)),
            ("triangle", offset_of!(GpuTriangle, triangle)),
            ("v1", offset_of!(GpuTriangle, v1)),
            ("material", offset_of!(GpuTriangle, material)),
            ("v2", offset_of!(GpuTriangle, v2)),
            ("unshadowed", offset_of!(GpuTriangle, unshadowed)),
        ],
    );
    assert_wgsl_layout(
        "cast",
        "CastRay",
        size_of::<CastRay>(),
        &[
            ("origin", offset_of!(CastRay, origin)),
            ("tmin", offset_of!(CastRay, tmin)),
            ("dir", offset_of!(CastRay, dir)),
            ("tmax", offset_of!(CastRay, tmax)),
        ],
    );
    assert_wgsl_layout(
        "triangles",
        "Instance",
        size_of::<GpuInstance>(),
        &[
            ("to_mesh", offset_of!(GpuInstance, to_mesh)),
            ("to_world", offset_of!(GpuInstance, to_world)),
            ("normal_x", offset_of!(GpuInstance, normal_x)),
            ("root", offset_of!(GpuInstance, root)),
            ("normal_y", offset_of!(GpuInstance, normal_y)),
            ("id_base", offset_of!(GpuInstance, id_base)),
            ("normal_z", offset_of!(GpuInstance, normal_z)),
            ("first", offset_of!(GpuInstance, first)),
            ("motion", offset_of!(GpuInstance, motion)),
        ],
    );
    assert_wgsl_layout(
        "shade",
        "Material",
        size_of::<GpuMaterial>(),
        &[
            ("diffuse", offset_of!(GpuMaterial, diffuse)),
            ("surface", offset_of!(GpuMaterial, surface)),
            ("specular", offset_of!(GpuMaterial, specular)),
            ("shininess", offset_of!(GpuMaterial, shininess)),
            ("emission", offset_of!(GpuMaterial, emission)),
            ("ior", offset_of!(GpuMaterial, ior)),
            ("transmission", offset_of!(GpuMaterial, transmission)),
            ("texture", offset_of!(GpuMaterial, texture)),
            ("opacity", offset_of!(GpuMaterial, opacity)),
            ("texture_width", offset_of!(GpuMaterial, texture_width)),
            ("texture_height", offset_of!(GpuMaterial, texture_height)),
            ("texture_levels", offset_of!(GpuMaterial, texture_levels)),
        ],
    );
    assert_wgsl_layout(
        "shade",
        "Light",
        size_of::<GpuLight>(),
        &[
            ("vector", offset_of!(GpuLight, vector)),
            ("kind", offset_of!(GpuLight, kind)),
            ("colour", offset_of!(GpuLight, colour)),
            ("shadow_layer", offset_of!(GpuLight, shadow_layer)),
        ],
    );
    assert_wgsl_layout(
        "shade",
        "Shading",
        size_of::<Shading>(),
        &[
            ("sky", offset_of!(Shading, sky)),
            ("light_count", offset_of!(Shading, light_count)),
            ("ambient", offset_of!(Shading, ambient)),
            ("max_depth", offset_of!(Shading, max_depth)),
            ("lights_at", offset_of!(Shading, lights_at)),
            ("materials_at", offset_of!(Shading, materials_at)),
            ("pad", offset_of!(Shading, pad)),
        ],
    );
    assert_wgsl_layout(
        "trace",
        "Frame",
        size_of::<Frame>(),
        &[
            ("right", offset_of!(Frame, right)),
            ("down", offset_of!(Frame, down)),
            ("forward", offset_of!(Frame, forward)),
            ("eye", offset_of!(Frame, eye)),
            ("offset", offset_of!(Frame, offset)),
            ("motion", offset_of!(Frame, motion)),
            ("shutter", offset_of!(Frame, shutter)),
            ("knots", offset_of!(Frame, knots)),
        ],
    );
    assert_wgsl_layout(
        "trace",
        "Knot",
        size_of::<Knot>(),
        &[
            ("rotation", offset_of!(Knot, rotation)),
            ("position", offset_of!(Knot, position)),
        ],
    );
}

/// `AdaptiveParams` in Rust and WGSL have the same size and field offsets.
#[test]
fn adaptive_params_layout_matches_wgsl() {
    assert_eq!(size_of::<AdaptiveParams>(), 48);
    assert_wgsl_layout(
        "adaptive",
        "AdaptiveParams",
        size_of::<AdaptiveParams>(),
        &[
            ("threshold", offset_of!(AdaptiveParams, threshold)),
            ("normal_cosine", offset_of!(AdaptiveParams, normal_cosine)),
            ("plane_distance", offset_of!(AdaptiveParams, plane_distance)),
            ("_pad0", offset_of!(AdaptiveParams, _pad0)),
            ("lattice", offset_of!(AdaptiveParams, lattice)),
            ("blocks", offset_of!(AdaptiveParams, blocks)),
            ("half_lattice", offset_of!(AdaptiveParams, half_lattice)),
            ("halves", offset_of!(AdaptiveParams, halves)),
        ],
    );
}

/// `LensParams` in Rust and WGSL have the same size and field offsets (naga's layout).
#[test]
fn lens_params_layout_matches_wgsl() {
    assert_wgsl_layout(
        "lens",
        "LensParams",
        size_of::<LensParams>(),
        &[
            ("f", offset_of!(LensParams, f)),
            ("k1_over_f", offset_of!(LensParams, k1_over_f)),
            ("rate", offset_of!(LensParams, rate)),
            ("r_max", offset_of!(LensParams, r_max)),
            ("theta_max", offset_of!(LensParams, theta_max)),
            ("width", offset_of!(LensParams, width)),
            ("height", offset_of!(LensParams, height)),
            ("mask_limit", offset_of!(LensParams, mask_limit)),
            ("intrinsics", offset_of!(LensParams, intrinsics)),
            ("coefficients", offset_of!(LensParams, coefficients)),
            ("affine", offset_of!(LensParams, affine)),
        ],
    );
}

#[test]
fn raster_structs_match_their_wgsl_twins() {
    assert_wgsl_layout(
        "raster",
        "Views",
        size_of::<Views>(),
        &[
            ("clip", offset_of!(Views, clip)),
            ("regions", offset_of!(Views, regions)),
            ("eye", offset_of!(Views, eye)),
        ],
    );
    assert_wgsl_layout(
        "raster",
        "ShadowView",
        size_of::<ShadowView>(),
        &[
            ("clip", offset_of!(ShadowView, clip)),
            ("texel", offset_of!(ShadowView, texel)),
        ],
    );
}
