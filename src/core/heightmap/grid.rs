//! The grid's geometry: node spacing, extent and the cell under a point.

/// Grid geometry of the height map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub x_min: f64,
    pub y_min: f64,
    pub dx: f64,
    pub dy: f64,
    pub nx: usize,
    pub ny: usize,
    /// `1/dx`, `1/dy` and the last cell's far edge in cell units, for queries.
    pub(super) inv_dx: f64,
    pub(super) inv_dy: f64,
    pub(super) u_max: f64,
    pub(super) v_max: f64,
}

impl Grid {
    pub fn new(x_min: f64, x_max: f64, y_min: f64, y_max: f64, nx: usize, ny: usize) -> Self {
        let dx = (x_max - x_min) / (nx - 1) as f64;
        let dy = (y_max - y_min) / (ny - 1) as f64;
        Self {
            x_min,
            y_min,
            dx,
            dy,
            nx,
            ny,
            inv_dx: 1.0 / dx,
            inv_dy: 1.0 / dy,
            u_max: (nx - 1) as f64,
            v_max: (ny - 1) as f64,
        }
    }

    pub fn x_max(&self) -> f64 {
        self.x_min + self.dx * (self.nx - 1) as f64
    }

    pub fn y_max(&self) -> f64 {
        self.y_min + self.dy * (self.ny - 1) as f64
    }

    /// Coordinates of node `(i, j)` (0-based; eqs 67-68).
    #[inline]
    pub fn node_xy(&self, i: usize, j: usize) -> (f64, f64) {
        (
            self.x_min + self.dx * i as f64,
            self.y_min + self.dy * j as f64,
        )
    }

    /// Range of node indices whose coordinates lie in `[lo, hi]`, clipped to the grid.
    pub fn node_range(
        &self,
        x_lo: f64,
        x_hi: f64,
        y_lo: f64,
        y_hi: f64,
    ) -> Option<(usize, usize, usize, usize)> {
        let i0 = ((x_lo - self.x_min) / self.dx).ceil().max(0.0);
        let i1 = ((x_hi - self.x_min) / self.dx)
            .floor()
            .min((self.nx - 1) as f64);
        let j0 = ((y_lo - self.y_min) / self.dy).ceil().max(0.0);
        let j1 = ((y_hi - self.y_min) / self.dy)
            .floor()
            .min((self.ny - 1) as f64);
        if !(i0 <= i1 && j0 <= j1) {
            return None;
        }
        Some((i0 as usize, i1 as usize, j0 as usize, j1 as usize))
    }

    /// The cell holding `(x, y)`: its lower-left node `(i, j)` and the
    /// position inside it in cell units `(fu, fv)` in [0, 1]; `None` outside
    /// the map. Every query of [`HeightMap`](super::HeightMap) goes through here, so all agree
    /// on which cell (and triangle) a point lies in.
    #[inline]
    pub fn cell(&self, x: f64, y: f64) -> Option<(usize, usize, f64, f64)> {
        let u = (x - self.x_min) * self.inv_dx;
        let v = (y - self.y_min) * self.inv_dy;
        if !(u >= 0.0 && v >= 0.0 && u <= self.u_max && v <= self.v_max) {
            return None;
        }
        // (in signed integers: `u` and `v` lie in [0, `u_max`] and [0,
        // `v_max`] here, far below 2^53, where both conversions are exact
        // and the signed ones take less code)
        let i = (u as i64).min(self.nx as i64 - 2);
        let j = (v as i64).min(self.ny as i64 - 2);
        Some((i as usize, j as usize, u - i as f64, v - j as f64))
    }

    /// Area a node stands for (one cell).
    pub fn cell_area(&self) -> f64 {
        self.dx * self.dy
    }
}
