//! The rock face that one or many discs cut: the height map and the
//! bookkeeping every disc adds to (rock removed, work done on the rock).
//!
//! A face is cheap to clone: the height map shares its tiles copy-on-write,
//! so an FMU-state snapshot of a bored face copies the tile directory only.

use super::error::Result;
use super::heightmap::{Grid, HeightMap};
use super::params::RockParams;
use super::rsf;

/// The rock and its bookkeeping (the part of the discrete state that all
/// discs share).
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    pub(crate) map: HeightMap,
    /// Committed rock removed so far, chips included \[m3\].
    pub(crate) excavated_volume: f64,
    /// Work of the discs on the rock so far \[J\].
    pub(crate) cutting_energy: f64,
}

/// The height-map grid the rock parameters declare.
pub fn grid_of(r: &RockParams) -> Grid {
    Grid::new(r.x_min, r.x_max, r.y_min, r.y_max, r.nx, r.ny)
}

impl Face {
    /// The initial face: flat at `rock.z0`, or read from `rock.initialSurface`.
    /// The parameters must have been validated.
    pub fn new(r: &RockParams) -> Result<Self> {
        let grid = grid_of(r);
        let map = if r.initial_surface.is_empty() {
            HeightMap::flat(grid, r.z0)
        } else {
            rsf::read(std::path::Path::new(&r.initial_surface), grid, r.z0)?
        };
        Ok(Self::from_map(map))
    }

    /// A face with this height map and nothing removed yet.
    pub fn from_map(map: HeightMap) -> Self {
        Self {
            map,
            excavated_volume: 0.0,
            cutting_energy: 0.0,
        }
    }

    pub fn map(&self) -> &HeightMap {
        &self.map
    }

    pub fn excavated_volume(&self) -> f64 {
        self.excavated_volume
    }

    pub fn cutting_energy(&self) -> f64 {
        self.cutting_energy
    }

    /// `cutting_energy / excavated_volume`, 0 while nothing was removed.
    pub fn specific_energy(&self) -> f64 {
        if self.excavated_volume > 0.0 {
            self.cutting_energy / self.excavated_volume
        } else {
            0.0
        }
    }

    /// Whether `other` stands on the same grid and base height (a state of
    /// one face may be restored into another only then).
    pub fn same_grid(&self, other: &Face) -> bool {
        self.map.grid() == other.map.grid() && self.map.base_height() == other.map.base_height()
    }
}
