//! Torture suite, grazing and coincident geometry: a plane seen at 89.9°,
//! two coplanar overlapping squares, and a box with 1e-6-thick walls.

use radiant::extract::Overrides;
use radiant::film::Image;
use radiant_tests::render_checked;

fn seeded(seed: u64) -> Overrides {
    Overrides {
        seed: Some(seed),
        ..Default::default()
    }
}

/// `scenes/hard/grazing-plane.yaml`: every camera ray meets a plate 0.06° to
/// 0.14° above grazing inside a furnace (albedo 0.5, emission 1, max_depth
/// 4), so every pixel must be 1 + ½ + ¼ + ⅛ = 1.875. A ray that re-hit the
/// plate it leaves would see the plate's back, which absorbs: a dark pixel.
#[test]
fn plane_seen_at_89_9_degrees_has_no_acne() {
    const EXPECTED: f32 = 1.875;
    // Measured at 16 spp (seeds 1 to 3): image mean within 0.1 %, every
    // pixel within 7 % (MIS noise). A pixel whose 16 paths all lost their
    // second segment would be at 1 or below.
    for seed in 1..=2 {
        let image = render_checked("scenes/hard/grazing-plane.yaml", seeded(seed));
        let mean = image.mean() as f32;
        let (lo, hi) = image
            .pixels
            .iter()
            .fold((f32::MAX, 0.0f32), |(lo, hi), p| (lo.min(p.x), hi.max(p.x)));
        eprintln!("seed {seed}: mean {mean}, pixels in [{lo}, {hi}]");
        assert!((mean / EXPECTED - 1.0).abs() < 0.01, "mean {mean}");
        assert!(
            lo > EXPECTED * 0.85 && hi < EXPECTED * 1.15,
            "pixels range over [{lo}, {hi}]"
        );
    }
}

/// Two coplanar squares overlap: which one a ray meets there is decided by
/// the last bits of two equal distances (z-fighting), as in Mitsuba and
/// pbrt, so the overlap shows a per-sample mixture of the two materials.
/// What Radiant guarantees, and this test asserts:
/// * each camera sample meets exactly one of the two squares — never
///   neither (a black speckle) nor both — so, per pixel, red + green of
///   the overlap equals what one yellow (red + green) rectangle covering
///   the union shows for the same samples (`coplanar-quads-union.yaml`);
/// * outside the overlap each square shows only its own colour;
/// * the result is deterministic: the same seed gives the same image.
#[test]
fn coplanar_overlapping_squares_show_exactly_one_surface_per_sample() {
    let quads = render_checked("scenes/hard/coplanar-quads.yaml", seeded(4));
    let union = render_checked("scenes/hard/coplanar-quads-union.yaml", seeded(4));
    let again = render_checked("scenes/hard/coplanar-quads.yaml", seeded(4));
    assert_eq!(quads.pixels, again.pixels, "not deterministic");
    let (mut red_only, mut green_only, mut mixed) = (0, 0, 0);
    for (q, u) in quads.pixels.iter().zip(&union.pixels) {
        assert_eq!(q.z, 0.0);
        // Hit points differ in the last bits between the triangles.
        assert!(
            (q.x + q.y - u.x).abs() <= 1e-4 * u.x.max(1e-3),
            "red {} + green {} != yellow {}",
            q.x,
            q.y,
            u.x
        );
        match (q.x > 0.0, q.y > 0.0) {
            (true, false) => red_only += 1,
            (false, true) => green_only += 1,
            (true, true) => mixed += 1,
            (false, false) => {}
        }
    }
    eprintln!("pixels: {red_only} red, {green_only} green, {mixed} mixed");
    // 40×20 pixels over x in [-1.007, 1.007]: the overlap, x in [-0.2,
    // 0.2], covers 8 columns (measured: 152 mixed pixels); 10 allow for
    // the columns it cuts.
    assert!(
        red_only >= 200 && green_only >= 200,
        "the squares are missing"
    );
    assert!(
        mixed <= 10 * 20,
        "{mixed} mixed pixels: colours mix outside the overlap"
    );
}

/// Counts pixels that are not exactly black.
fn lit_pixels(image: &Image) -> usize {
    image
        .pixels
        .iter()
        .filter(|p| **p != radiant_core::Rgb::ZERO)
        .count()
}

/// `scenes/hard/thin-box-*.yaml`: a box whose walls are two cubes 1e-6
/// apart, with the light on one side of the walls and the camera on the
/// other. Any light getting through would make a pixel non-black.
///
/// The known near-edge miss (a ray starting within about 1e-5 relative of
/// an edge, heading into the adjacent face, closer than the triangle
/// test's error bound on t) cannot leak here: the spawned ray then meets
/// the second wall, 1e-6 further, well beyond that bound. Measured: no lit
/// pixel in 32×32 pixels at 1024 spp (2 million paths of up to 6 segments).
#[test]
fn box_with_walls_1e_6_thick_lets_no_light_through() {
    for scene in [
        "scenes/hard/thin-box-camera-inside.yaml",
        "scenes/hard/thin-box-light-inside.yaml",
    ] {
        for seed in [1, 2] {
            let image = render_checked(scene, seeded(seed));
            assert_eq!(lit_pixels(&image), 0, "{scene}, seed {seed}: light leaked");
        }
    }
}
