//! Top-view footprints of solids in a uniform grid, so the clearance around a spot is
//! measured against the solids near it rather than every solid of the scene (a cell with
//! 10,000 cubes places things as fast as one with ten).

use std::collections::HashMap;

use super::Aabb;

/// Boxes bucketed by the grid cells their footprint (x, y) overlaps.
pub struct Footprints {
    boxes: Vec<Aabb>,
    cell: f32,
    cells: HashMap<(i32, i32), Vec<usize>>,
}

impl Footprints {
    /// Index `boxes` in cells of `cell` metres (the largest distance that will be asked
    /// is a good size: a query then reads at most nine cells).
    pub fn new(boxes: Vec<Aabb>, cell: f32) -> Self {
        let cell = cell.max(1e-3);
        let mut cells: HashMap<(i32, i32), Vec<usize>> = HashMap::new();
        for (i, b) in boxes.iter().enumerate() {
            let (x0, y0) = key(b.mins.x, b.mins.y, cell);
            let (x1, y1) = key(b.maxs.x, b.maxs.y, cell);
            for x in x0..=x1 {
                for y in y0..=y1 {
                    cells.entry((x, y)).or_default().push(i);
                }
            }
        }
        Footprints { boxes, cell, cells }
    }

    /// The smallest top-view distance from the rectangle centred at (`px`, `py`) with half
    /// sizes `hx` × `hy` to any box, capped at `cap` (boxes farther than `cap` cannot
    /// lower it, so only the cells within `cap` of the rectangle are read).
    pub fn gap(&self, (px, py): (f32, f32), (hx, hy): (f32, f32), cap: f32) -> f32 {
        let (x0, y0) = key(px - hx - cap, py - hy - cap, self.cell);
        let (x1, y1) = key(px + hx + cap, py + hy + cap, self.cell);
        let mut best = cap;
        for x in x0..=x1 {
            for y in y0..=y1 {
                for &i in self.cells.get(&(x, y)).into_iter().flatten() {
                    let b = &self.boxes[i];
                    let dx = (b.mins.x - (px + hx)).max(px - hx - b.maxs.x).max(0.0);
                    let dy = (b.mins.y - (py + hy)).max(py - hy - b.maxs.y).max(0.0);
                    best = best.min(dx.hypot(dy));
                }
            }
        }
        best
    }
}

fn key(x: f32, y: f32, cell: f32) -> (i32, i32) {
    ((x / cell).floor() as i32, (y / cell).floor() as i32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    fn unit_box(x: f32, y: f32) -> Aabb {
        Aabb::new(
            Point3::new(x, y, 0.0),
            Point3::new(x + 0.04, y + 0.04, 0.04),
        )
    }

    /// The grid answers exactly what measuring against every box answers.
    #[test]
    fn gap_matches_measuring_every_box() {
        let boxes: Vec<Aabb> = (0..400)
            .map(|i| unit_box(-1.0 + 0.13 * (i % 20) as f32, -1.0 + 0.11 * (i / 20) as f32))
            .collect();
        let grid = Footprints::new(boxes.clone(), 0.1);
        let brute = |px: f32, py: f32, hx: f32, hy: f32, cap: f32| {
            boxes
                .iter()
                .map(|b| {
                    let dx = (b.mins.x - (px + hx)).max(px - hx - b.maxs.x).max(0.0);
                    let dy = (b.mins.y - (py + hy)).max(py - hy - b.maxs.y).max(0.0);
                    dx.hypot(dy)
                })
                .fold(f32::INFINITY, f32::min)
                .min(cap)
        };
        for i in 0..60 {
            for j in 0..60 {
                let (px, py) = (-1.2 + 0.047 * i as f32, -1.2 + 0.043 * j as f32);
                assert_eq!(
                    grid.gap((px, py), (0.02, 0.03), 0.1),
                    brute(px, py, 0.02, 0.03, 0.1),
                    "at ({px}, {py})"
                );
            }
        }
        assert_eq!(
            Footprints::new(Vec::new(), 0.1).gap((0.0, 0.0), (0.1, 0.1), 0.1),
            0.1
        );
    }
}
