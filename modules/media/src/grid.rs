//! The `grid` medium: density on a regular 3D grid (a Mitsuba `.vol`
//! file, [`VolGrid`]) with trilinear lookup between cell centres, placed
//! in an axis-aligned box, times the coefficients written. A coarse
//! majorant grid (the largest density each of its cells' lookups can
//! reach) bounds it; the integrator samples distances by delta tracking
//! and estimates transmittance by ratio tracking against it, walking its
//! cells along each ray with a 3D DDA (Amanatides & Woo).

use crate::coefficients::{medium_docs, medium_params};
use crate::vol::VolGrid;
use radiant_core::glam::{DVec3, Vec3};
use radiant_core::medium::DensityField;
use radiant_core::params::Spanned;
use radiant_core::{
    BuildContext, Coefficients, GpuModule, GpuParams, Medium, Numbers, ParamDoc, ParamError,
    Params, Profile, Registry,
};

medium_params!(GridParams {
    filename: Spanned<String>,
    min: Option<Spanned<Numbers<3>>>,
    max: Option<Spanned<Numbers<3>>>,
    majorant_cells: Option<Spanned<u32>>,
});

const DOCS: &[ParamDoc] = medium_docs!(
    "Extinction σt where the grid's value is 1 (with `albedo`).",
    ParamDoc {
        name: "filename",
        ty: "path",
        default: "required",
        doc: "A Mitsuba `.vol` file of one 32-bit float channel: the density at the voxel centres (finite, ≥ 0).",
    },
    ParamDoc {
        name: "min",
        ty: "[x, y, z]",
        default: "the file's box",
        doc: "World-space corner of the grid's box (with `max`); the density is 0 outside it.",
    },
    ParamDoc {
        name: "max",
        ty: "[x, y, z]",
        default: "the file's box",
        doc: "The opposite corner (greater than `min` on every axis).",
    },
    ParamDoc {
        name: "majorant_cells",
        ty: "integer, 1 to 256",
        default: "16",
        doc: "Cells per axis of the majorant grid (at most the grid's resolution): more cells, tighter bounds for sparse grids.",
    },
);

/// A density grid in render space with its majorant grid.
#[derive(Debug, Clone, PartialEq)]
pub struct DensityGrid {
    resolution: [usize; 3],
    values: Vec<f32>,
    /// Render-space corner and size of the box.
    origin: Vec3,
    size: Vec3,
    /// Majorant cells per axis and their bounds (x fastest).
    cells: [usize; 3],
    majorants: Vec<f32>,
}

impl DensityGrid {
    /// A grid of `values` (x fastest) at `resolution`, filling the
    /// render-space box from `origin` of extent `size`, with at most
    /// `majorant_cells` majorant cells per axis.
    pub fn new(
        resolution: [usize; 3],
        values: Vec<f32>,
        (origin, size): (Vec3, Vec3),
        majorant_cells: usize,
    ) -> Self {
        let cells = resolution.map(|r| r.min(majorant_cells).max(1));
        let mut grid = Self {
            resolution,
            values,
            origin,
            size,
            cells,
            majorants: vec![0.0; cells[0] * cells[1] * cells[2]],
        };
        // Each majorant cell covers [c/M, (c+1)/M] of the box; a lookup
        // there interpolates voxels floor(lo)..=floor(hi)+1 in voxel
        // coordinates x = u·n − 0.5 (clamped to the grid).
        let range = |axis: usize, c: usize| {
            let (n, m) = (resolution[axis] as f64, cells[axis] as f64);
            let lo = (c as f64 / m * n - 0.5).floor().max(0.0) as usize;
            let hi = (((c + 1) as f64 / m * n - 0.5).floor() as isize + 1)
                .clamp(0, resolution[axis] as isize - 1) as usize;
            lo.min(resolution[axis] - 1)..=hi
        };
        for cz in 0..cells[2] {
            for cy in 0..cells[1] {
                for cx in 0..cells[0] {
                    let mut top = 0.0f32;
                    for z in range(2, cz) {
                        for y in range(1, cy) {
                            for x in range(0, cx) {
                                top = top.max(grid.voxel(x, y, z));
                            }
                        }
                    }
                    grid.majorants[(cz * cells[1] + cy) * cells[0] + cx] = top;
                }
            }
        }
        grid
    }

    #[inline]
    fn voxel(&self, x: usize, y: usize, z: usize) -> f32 {
        self.values[(z * self.resolution[1] + y) * self.resolution[0] + x]
    }
}

/// The lower voxel index and weight of the upper one along an axis of `n`
/// voxels at box coordinate `u` ∈ [0, 1] (cell centres, clamped at edges).
#[inline]
fn axis(u: f32, n: usize) -> (usize, usize, f32) {
    let x = u * n as f32 - 0.5;
    let i = x.floor();
    let f = x - i;
    let last = n as isize - 1;
    let i = i as isize;
    (
        i.clamp(0, last) as usize,
        (i + 1).clamp(0, last) as usize,
        f,
    )
}

impl DensityField for DensityGrid {
    fn density(&self, p: Vec3) -> f32 {
        let u = (p - self.origin) / self.size;
        if u.min_element() < 0.0 || u.max_element() > 1.0 || !u.is_finite() {
            return 0.0;
        }
        let (x0, x1, fx) = axis(u.x, self.resolution[0]);
        let (y0, y1, fy) = axis(u.y, self.resolution[1]);
        let (z0, z1, fz) = axis(u.z, self.resolution[2]);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let plane = |z| {
            lerp(
                lerp(self.voxel(x0, y0, z), self.voxel(x1, y0, z), fx),
                lerp(self.voxel(x0, y1, z), self.voxel(x1, y1, z), fx),
                fy,
            )
        };
        lerp(plane(z0), plane(z1), fz).max(0.0)
    }

    fn majorants(
        &self,
        o: Vec3,
        d: Vec3,
        t_max: f32,
        visit: &mut dyn FnMut(f32, f32, f32) -> bool,
    ) {
        // In box coordinates u = (p − origin)/size ∈ [0, 1]³ (the same t).
        let uo = (o - self.origin) / self.size;
        let ud = d / self.size;
        let (mut t0, mut t1) = (0.0f32, t_max);
        for a in 0..3 {
            let inv = 1.0 / ud[a];
            let (mut near, mut far) = ((0.0 - uo[a]) * inv, (1.0 - uo[a]) * inv);
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            // NaN (a ray in a face's plane, parallel to it) leaves t as is.
            t0 = if near > t0 { near } else { t0 };
            t1 = if far < t1 { far } else { t1 };
        }
        if t0 >= t1 {
            return;
        }
        let m = self.cells.map(|c| c as isize);
        let start = uo + ud * t0;
        let mut cell = [0isize; 3];
        let mut next = [f32::INFINITY; 3];
        let mut delta = [f32::INFINITY; 3];
        let mut step = [0isize; 3];
        for a in 0..3 {
            let mf = m[a] as f32;
            cell[a] = ((start[a] * mf).floor() as isize).clamp(0, m[a] - 1);
            if ud[a] > 0.0 {
                step[a] = 1;
                next[a] = t0 + (((cell[a] + 1) as f32 / mf) - start[a]) / ud[a];
                delta[a] = 1.0 / (mf * ud[a]);
            } else if ud[a] < 0.0 {
                step[a] = -1;
                next[a] = t0 + ((cell[a] as f32 / mf) - start[a]) / ud[a];
                delta[a] = -1.0 / (mf * ud[a]);
            }
        }
        let mut t = t0;
        loop {
            let a = if next[0] <= next[1] && next[0] <= next[2] {
                0
            } else if next[1] <= next[2] {
                1
            } else {
                2
            };
            let end = next[a].min(t1);
            let index = ((cell[2] * m[1] + cell[1]) * m[0] + cell[0]) as usize;
            if end > t && !visit(t, end, self.majorants[index]) {
                return;
            }
            if end >= t1 {
                return;
            }
            t = end;
            cell[a] += step[a];
            next[a] += delta[a];
            if cell[a] < 0 || cell[a] >= m[a] {
                return;
            }
        }
    }
}

/// A heterogeneous medium on a density grid.
pub struct Grid {
    coefficients: Coefficients,
    grid: DensityGrid,
}

impl Medium for Grid {
    fn coefficients(&self) -> Coefficients {
        self.coefficients
    }

    fn profile(&self) -> Profile<'_> {
        Profile::Field(&self.grid)
    }

    fn gpu(&self) -> Option<GpuModule> {
        let g = &self.grid;
        let words = |v: [usize; 3]| {
            GpuParams::new()
                .u32(v[0] as u32)
                .u32(v[1] as u32)
                .u32(v[2] as u32)
        };
        let params = words(g.resolution)
            .vec3(g.origin)
            .vec3(g.size)
            .append(&words(g.cells))
            .f32s(g.values.iter().copied())
            .f32s(g.majorants.iter().copied());
        Some(crate::gpu::medium(
            "grid",
            include_str!("grid.wgsl"),
            &self.coefficients,
            params,
        ))
    }
}

fn corner(c: &Option<Spanned<Numbers<3>>>, file: [f32; 3]) -> Result<DVec3, ParamError> {
    match c {
        None => Ok(Vec3::from_array(file).as_dvec3()),
        Some(c) => {
            let v = DVec3::from_array(c.0);
            if v.is_finite() {
                Ok(v)
            } else {
                Err(ParamError::at(
                    c.span(),
                    format!("expected a finite point, found {v}"),
                ))
            }
        }
    }
}

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<Grid, ParamError> {
    let p: GridParams = params.parse()?;
    let coefficients = p.shared().coefficients()?;
    let path = ctx.scene_dir.join(&*p.filename);
    let file = VolGrid::read(&path).map_err(|e| ParamError::at(p.filename.span(), e))?;
    let (min, max) = (
        corner(&p.min, file.bounds[0])?,
        corner(&p.max, file.bounds[1])?,
    );
    if !max.cmpgt(min).all() {
        let at = p
            .max
            .as_ref()
            .or(p.min.as_ref())
            .map_or(p.filename.span(), |s| s.span());
        return Err(ParamError::at(
            at,
            format!(
                "the grid's box needs `max` greater than `min` on every axis: min {min}, max {max}"
            ),
        ));
    }
    let cells = match &p.majorant_cells {
        None => 16,
        Some(c) if (1..=256).contains(&**c) => **c as usize,
        Some(c) => {
            return Err(ParamError::at(
                c.span(),
                format!("`majorant_cells` must be 1 to 256, found {}", **c),
            ));
        }
    };
    let origin = ctx.to_render(min);
    let size = (max - min).as_vec3();
    Ok(Grid {
        coefficients,
        grid: DensityGrid::new(file.resolution, file.values, (origin, size), cells),
    })
}

pub(crate) fn register(registry: &mut Registry) {
    let info = crate::medium_info(
        "grid",
        "Heterogeneous density on a 3D grid (Mitsuba `.vol`), trilinear, tracked against a majorant grid; its `phase:` as for `homogeneous`.",
        DOCS,
    );
    crate::register_medium(registry, info, build);
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the grids and parameters are the test's own.
    use super::*;
    use radiant_core::params::check_param_docs;

    #[test]
    fn documented_parameters_match() {
        check_param_docs::<GridParams>(DOCS).unwrap();
    }

    /// A 4×3×2 grid of pseudo-random values over the box [−1, 1]³.
    fn grid(cells: usize) -> DensityGrid {
        let values: Vec<f32> = (0..24u32)
            .map(|i| (radiant_core::hash::hash_u32(i) % 1000) as f32 / 100.0)
            .collect();
        DensityGrid::new(
            [4, 3, 2],
            values,
            (Vec3::splat(-1.0), Vec3::splat(2.0)),
            cells,
        )
    }

    #[test]
    fn lookups_interpolate_cell_centres() {
        let g = grid(2);
        // The centre of voxel (1, 2, 0): u = ((1.5)/4, 2.5/3, 0.5/2).
        let p = Vec3::new(1.5 / 4.0, 2.5 / 3.0, 0.25) * 2.0 - 1.0;
        assert!((g.density(p) - g.voxel(1, 2, 0)).abs() < 1e-4);
        // Halfway between voxels (0, 0, 0) and (1, 0, 0).
        let p = Vec3::new(1.0 / 4.0, 0.5 / 3.0, 0.25) * 2.0 - 1.0;
        let mid = 0.5 * (g.voxel(0, 0, 0) + g.voxel(1, 0, 0));
        assert!((g.density(p) - mid).abs() < 1e-4);
        assert_eq!(g.density(Vec3::new(1.5, 0.0, 0.0)), 0.0);
    }

    #[test]
    fn majorant_segments_cover_the_box_and_bound_the_density() {
        for cells in [1, 2, 16] {
            let g = grid(cells);
            let mut rng = radiant_core::medium::Stream::new(cells as u32, 0, 0, 0);
            for _ in 0..2000 {
                let mut r = || rng.next_f32() * 2.0 - 1.0;
                let o = Vec3::new(r(), r(), r()) * 2.0;
                let d = Vec3::new(r(), r(), r()).normalize();
                let t_max = 5.0;
                let mut last = 0.0f32;
                let mut covered = 0.0f32;
                g.majorants(o, d, t_max, &mut |t0, t1, bound| {
                    assert!(t0 >= last - 1e-5 && t1 > t0 && t1 <= t_max, "{t0} {t1}");
                    for k in 0..16 {
                        let t = t0 + (t1 - t0) * (k as f32 + 0.5) / 16.0;
                        let rho = g.density(o + d * t);
                        assert!(rho <= bound + 1e-4, "ρ {rho} above its bound {bound}");
                    }
                    covered += t1 - t0;
                    last = t1;
                    true
                });
                // The segments cover the ray's chord through the box.
                let n = 4000;
                let inside = (0..n)
                    .filter(|&k| {
                        let t = t_max * (k as f32 + 0.5) / n as f32;
                        let u = (o + d * t + 1.0) / 2.0;
                        u.min_element() > 0.0 && u.max_element() < 1.0
                    })
                    .count() as f32
                    * t_max
                    / n as f32;
                assert!((covered - inside).abs() < 0.01, "{covered} vs {inside}");
            }
        }
    }
}
