//! The GPU backend renders what the CPU backend renders: the same scenes
//! through both, compared by channel means and block means.
//!
//! Both run the same estimator with the same sampler dimensions and the
//! same film (filter splatting, the scenes' default, and once filter
//! importance sampling), so their sample paths mostly coincide and the
//! images differ only where float rounding sends a path elsewhere: far
//! less than the noise, which lets the tolerances catch a 2 % energy
//! error in one module (each test also checks that it would).

use radiant::backend::gpu::BvhLayout;
use radiant::extract::Overrides;
use radiant::settings::FilterSampling;
use radiant_tests::Tolerances;
use radiant_tests::gpu::{assert_agrees, render_both, render_both_with_bvh};

/// Renders `scene` at `size`² pixels and `spp` on both backends and checks
/// that the GPU image matches the CPU one within `tolerances`, and that a
/// 2 % scale of the GPU image would not.
fn agrees(scene: &str, size: u32, spp: u32, tolerances: Tolerances) {
    agrees_with(scene, [size, size], spp, tolerances, None);
}

/// [`agrees`] at `width`×`height` pixels with the film's filter sampling
/// set to `sampling`.
fn agrees_with(
    scene: &str,
    [width, height]: [u32; 2],
    spp: u32,
    tolerances: Tolerances,
    sampling: Option<FilterSampling>,
) {
    let overrides = Overrides {
        width: Some(width),
        height: Some(height),
        spp: Some(spp),
        filter_sampling: sampling,
        ..Overrides::default()
    };
    assert_agrees(scene, render_both(scene, &overrides), tolerances);
}

/// Channel means within 0.6 %, 8×8 blocks within 6 %.
const CLOSE: Tolerances = Tolerances {
    channel_mean: 0.006,
    block: 0.06,
};

#[test]
fn cornell_box() {
    agrees("scenes/cornell-box.yaml", 48, 64, CLOSE);
}

/// The compressed wide BVH's traversal renders what the CPU renders, at
/// the Cornell box's size and at 10⁵ times it (its error bound scales).
#[test]
fn wide_bvh() {
    for scene in [
        "scenes/cornell-box.yaml",
        "scenes/hard/cornell-scaled-1e5.yaml",
    ] {
        let overrides = Overrides {
            width: Some(48),
            height: Some(48),
            spp: Some(64),
            ..Overrides::default()
        };
        let images = render_both_with_bvh(scene, &overrides, BvhLayout::Wide);
        assert_agrees(scene, images, CLOSE);
    }
}

#[test]
fn cornell_box_with_filter_importance_sampling() {
    agrees_with(
        "scenes/cornell-box.yaml",
        [48, 48],
        64,
        CLOSE,
        Some(FilterSampling::Importance),
    );
}

#[test]
fn glass() {
    agrees("scenes/glass.yaml", 48, 64, CLOSE);
}

#[test]
fn rough_metal() {
    agrees("scenes/rough-metal.yaml", 48, 64, CLOSE);
}

#[test]
fn torture_scale_1e5() {
    agrees("scenes/hard/cornell-scaled-1e5.yaml", 48, 64, CLOSE);
}

#[test]
fn torture_grazing_plane() {
    agrees("scenes/hard/grazing-plane.yaml", 48, 64, CLOSE);
}

#[test]
fn point_light() {
    agrees("scenes/hard/tiny-light-point.yaml", 48, 64, CLOSE);
}

#[test]
fn plastic() {
    agrees("scenes/plastic.yaml", 48, 64, CLOSE);
}

#[test]
fn environment() {
    agrees("scenes/environment.yaml", 48, 64, CLOSE);
}

#[test]
fn spot_and_directional_lights() {
    agrees("scenes/spot-directional.yaml", 48, 64, CLOSE);
}

#[test]
fn depth_of_field() {
    agrees("scenes/depth-of-field.yaml", 48, 64, CLOSE);
}

#[test]
fn textured_mesh() {
    agrees("tests/data/uv/mesh.yaml", 48, 64, CLOSE);
}

#[test]
fn torture_glass_ior_1() {
    agrees("scenes/hard/glass-ior-1.yaml", 48, 64, CLOSE);
}

/// Anisotropic GGX on a sphere and on a mesh with MikkTSpace tangents:
/// shading frames oriented by the parametrization.
#[test]
fn anisotropic_tangent_frames() {
    agrees_with(
        "tests/data/tangents/anisotropic.yaml",
        [64, 32],
        64,
        CLOSE,
        None,
    );
}

/// A normal map on rectangles (turned) and on a mesh with tangents.
#[test]
fn normal_map() {
    agrees_with(
        "tests/data/tangents/normal-map.yaml",
        [96, 32],
        64,
        CLOSE,
        None,
    );
}

/// A bump map on rectangles, differentiated along their ∂p/∂u, ∂p/∂v.
#[test]
fn bump_map() {
    agrees_with("tests/data/tangents/bump.yaml", [64, 32], 64, CLOSE, None);
}
