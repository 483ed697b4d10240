//! Writes the deforming mesh of the animation demo: a flag waving from a
//! pole, one OBJ file per frame (`cloth_0000.obj` …), with vertex normals
//! and texture coordinates, every frame the same triangles.
//!
//! ```text
//! cargo run --release --example cloth [-- OUT_FOLDER [LAST_FRAME]]
//! ```
//!
//! (defaults: `scenes/animation/cloth`, frames 0 to 49 at 24 frames per
//! second — the demo renders frames 1 to 48, and its shutter reaches a
//! little into the frames around them).

use std::fmt::Write as _;
use std::path::PathBuf;

/// Vertices along the flag (from the pole) and down it.
const COLUMNS: usize = 48;
const ROWS: usize = 32;
/// The flag's length and height.
const LENGTH: f64 = 1.6;
const HEIGHT: f64 = 1.0;
/// Frames per second (the demo scene's).
const FPS: f64 = 24.0;

/// A point of the flag at (u along, v down) in [0, 1]², at `time` seconds:
/// a travelling wave whose amplitude grows away from the pole, a slow
/// flutter of the free corner, and a sag under gravity.
fn point(u: f64, v: f64, time: f64) -> [f64; 3] {
    let phase = 7.0 * u - 5.0 * time + 1.3 * v;
    let amplitude = 0.26 * u * (0.8 + 0.2 * (2.1 * time).sin());
    let z = amplitude * phase.sin() + 0.04 * u * u * (11.0 * u + 3.0 * time + 4.0 * v).sin();
    // The cloth keeps roughly its length: waving pulls the far end in.
    let x = LENGTH * u - 0.08 * u * u * (1.0 + (2.0 * phase).cos());
    let y = -HEIGHT * v - 0.12 * u * u * v;
    [x, y, z]
}

/// The OBJ text of frame `frame`.
fn frame(frame: i64) -> String {
    let time = frame as f64 / FPS;
    let mut obj = String::with_capacity(COLUMNS * ROWS * 96);
    let at = |i: usize, j: usize| {
        point(
            i as f64 / (COLUMNS - 1) as f64,
            j as f64 / (ROWS - 1) as f64,
            time,
        )
    };
    for j in 0..ROWS {
        for i in 0..COLUMNS {
            let p = at(i, j);
            let _ = writeln!(obj, "v {:.6} {:.6} {:.6}", p[0], p[1], p[2]);
        }
    }
    // Normals from the neighbours' central differences.
    for j in 0..ROWS {
        for i in 0..COLUMNS {
            let (a, b) = (at(i.saturating_sub(1), j), at((i + 1).min(COLUMNS - 1), j));
            let (c, d) = (at(i, j.saturating_sub(1)), at(i, (j + 1).min(ROWS - 1)));
            let du = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let dv = [d[0] - c[0], d[1] - c[1], d[2] - c[2]];
            // du × dv points to −z for a flat flag (v runs down): the
            // front faces +z, so take dv × du.
            let n = [
                dv[1] * du[2] - dv[2] * du[1],
                dv[2] * du[0] - dv[0] * du[2],
                dv[0] * du[1] - dv[1] * du[0],
            ];
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-12);
            let _ = writeln!(obj, "vn {:.6} {:.6} {:.6}", n[0] / l, n[1] / l, n[2] / l);
        }
    }
    for j in 0..ROWS {
        for i in 0..COLUMNS {
            let (u, v) = (
                i as f64 / (COLUMNS - 1) as f64,
                j as f64 / (ROWS - 1) as f64,
            );
            let _ = writeln!(obj, "vt {u:.6} {:.6}", 1.0 - v);
        }
    }
    for j in 0..ROWS - 1 {
        for i in 0..COLUMNS - 1 {
            let a = j * COLUMNS + i + 1;
            let (b, c, d) = (a + 1, a + COLUMNS + 1, a + COLUMNS);
            // Counter-clockwise seen from +z (v runs down the flag).
            let _ = writeln!(obj, "f {a}/{a}/{a} {d}/{d}/{d} {c}/{c}/{c}");
            let _ = writeln!(obj, "f {a}/{a}/{a} {c}/{c}/{c} {b}/{b}/{b}");
        }
    }
    obj
}

fn main() -> std::io::Result<()> {
    let mut args = std::env::args().skip(1);
    let folder = PathBuf::from(
        args.next()
            .unwrap_or_else(|| "scenes/animation/cloth".into()),
    );
    let last: i64 = match args.next() {
        Some(n) => n.parse().map_err(|_| {
            std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("LAST_FRAME must be a whole number, found `{n}`"),
            )
        })?,
        None => 49,
    };
    std::fs::create_dir_all(&folder)?;
    for f in 0..=last {
        std::fs::write(folder.join(format!("cloth_{f:04}.obj")), frame(f))?;
    }
    println!(
        "wrote frames 0 to {last} of a {}-triangle flag to {}",
        2 * (COLUMNS - 1) * (ROWS - 1),
        folder.display()
    );
    Ok(())
}
