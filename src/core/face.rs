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

    /// A face with this height map and nothing removed yet (its tiles'
    /// height bounds found from the nodes set: `HeightMap::refresh_bounds`).
    pub fn from_map(mut map: HeightMap) -> Self {
        map.refresh_bounds();
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

/// Little-endian writers and a checked reader for the head's state blob
/// (the layout of the single-disc model's, which model.rs writes itself).
pub(crate) mod blob {
    use super::super::chip_heightmap::ChipState;
    use super::super::disc::DiscState;
    use super::super::error::{KerfError, Result};
    use super::super::face::Face;
    use super::super::heightmap::{Grid, HeightMap, TILE};
    use super::super::pose::Pose;

    pub fn bad(why: &str) -> KerfError {
        KerfError::BadState(why.to_string())
    }

    pub fn f64s(v: &mut Vec<u8>, xs: &[f64]) {
        for x in xs {
            v.extend_from_slice(&x.to_le_bytes());
        }
    }

    pub fn u64s(v: &mut Vec<u8>, xs: &[u64]) {
        for x in xs {
            v.extend_from_slice(&x.to_le_bytes());
        }
    }

    /// Grid, base height, excavated volume and cutting energy.
    pub fn face_header(v: &mut Vec<u8>, face: &Face) {
        rock_header(v, &face.map, face.excavated_volume, face.cutting_energy);
    }

    /// [`face_header`] from its parts (the one-disc model's state).
    pub fn rock_header(v: &mut Vec<u8>, map: &HeightMap, excavated: f64, energy: f64) {
        let g = map.grid();
        u64s(v, &[g.nx as u64, g.ny as u64]);
        f64s(
            v,
            &[
                g.x_min,
                g.y_min,
                g.dx,
                g.dy,
                map.base_height(),
                excavated,
                energy,
            ],
        );
    }

    /// Last cut and chips of one disc.
    pub fn disc_state(v: &mut Vec<u8>, s: &DiscState) {
        match s.last_cut {
            Some(p) => {
                v.push(1);
                f64s(v, &p.to_array());
            }
            None => v.push(0),
        }
        f64s(v, &[s.last_power]);
        let c = &s.chips;
        f64s(v, &[c.travel, c.next, c.volume]);
        u64s(v, &[c.index, c.count]);
        match c.last_low {
            Some(p) => {
                v.push(1);
                f64s(v, &p);
            }
            None => v.push(0),
        }
        u64s(v, &[u64::from(c.quiet)]);
    }

    /// Bytes of one tile: index, heights, cut mask, height bound.
    const TILE_BYTES: usize = 8 + TILE * TILE * 8 + HeightMap::MASK_WORDS * 8 + 8;

    /// The touched tiles only, with their cut masks and the height bound the
    /// map keeps for each (the cut windows and the contact's arc walk start
    /// from it: without it a state read back would replay differently).
    pub fn tiles(v: &mut Vec<u8>, map: &HeightMap) {
        let tiles: Vec<(usize, &[f64], &[u64])> = map.touched_tiles().collect();
        v.reserve(8 + tiles.len() * TILE_BYTES);
        u64s(v, &[tiles.len() as u64]);
        for (k, z, cut) in tiles {
            u64s(v, &[k as u64]);
            f64s(v, z);
            u64s(v, cut);
            f64s(v, &[map.tile_bound(k)]);
        }
    }

    pub struct Reader<'a> {
        pub bytes: &'a [u8],
        pub pos: usize,
    }

    impl<'a> Reader<'a> {
        pub fn new(bytes: &'a [u8]) -> Self {
            Self { bytes, pos: 0 }
        }

        pub fn take(&mut self, n: usize) -> Result<&'a [u8]> {
            let s = self
                .bytes
                .get(self.pos..self.pos + n)
                .ok_or_else(|| bad("the blob is truncated"))?;
            self.pos += n;
            Ok(s)
        }

        pub fn u8(&mut self) -> Result<u8> {
            Ok(self.take(1)?[0])
        }

        pub fn u32(&mut self) -> Result<u32> {
            Ok(u32::from_le_bytes(self.take(4)?.try_into().unwrap()))
        }

        pub fn u64(&mut self) -> Result<u64> {
            Ok(u64::from_le_bytes(self.take(8)?.try_into().unwrap()))
        }

        pub fn f64(&mut self) -> Result<f64> {
            Ok(f64::from_le_bytes(self.take(8)?.try_into().unwrap()))
        }

        pub fn end(&self) -> Result<()> {
            if self.pos != self.bytes.len() {
                return Err(bad("trailing bytes"));
            }
            Ok(())
        }

        /// Reads what [`face_header`] wrote and checks it against `grid`
        /// and `z0`; returns (excavated volume, cutting energy).
        pub fn face_header(&mut self, grid: &Grid, z0: f64) -> Result<(f64, f64)> {
            let (nx, ny) = (self.u64()?, self.u64()?);
            let mut f = [0f64; 7];
            for x in &mut f {
                *x = self.f64()?;
            }
            let same = nx == grid.nx as u64
                && ny == grid.ny as u64
                && f[0] == grid.x_min
                && f[1] == grid.y_min
                && f[2] == grid.dx
                && f[3] == grid.dy
                && f[4] == z0;
            if !same {
                return Err(bad("the state was saved for another rock grid"));
            }
            if !(f[5].is_finite() && f[6].is_finite()) {
                return Err(bad("non-finite bookkeeping"));
            }
            Ok((f[5], f[6]))
        }

        /// Reads what [`disc_state`] wrote.
        pub fn disc_state(&mut self) -> Result<DiscState> {
            let last_cut = match self.u8()? {
                0 => None,
                1 => {
                    let mut q = [0f64; 6];
                    for x in &mut q {
                        *x = self.f64()?;
                    }
                    let pose = Pose::new(q[0], q[1], q[2], q[3], q[4], q[5]);
                    pose.validate()
                        .map_err(|_| bad("non-finite last cut pose"))?;
                    Some(pose)
                }
                _ => return Err(bad("bad last-cut flag")),
            };
            let last_power = self.f64()?;
            if !last_power.is_finite() {
                return Err(bad("non-finite last power"));
            }
            let mut cf = [0f64; 3];
            for x in &mut cf {
                *x = self.f64()?;
            }
            let index = self.u64()?;
            let count = self.u64()?;
            let last_low = match self.u8()? {
                0 => None,
                1 => {
                    let mut q = [0f64; 3];
                    for x in &mut q {
                        *x = self.f64()?;
                    }
                    Some(q)
                }
                _ => return Err(bad("bad chip flag")),
            };
            let quiet = u32::try_from(self.u64()?).map_err(|_| bad("bad chip boundary count"))?;
            if !cf
                .iter()
                .chain(last_low.iter().flatten())
                .all(|x| x.is_finite())
            {
                return Err(bad("non-finite chip state"));
            }
            let [travel, next, volume] = cf;
            Ok(DiscState {
                last_cut,
                last_power,
                chips: ChipState {
                    travel,
                    index,
                    next,
                    last_low,
                    count,
                    volume,
                    quiet,
                },
            })
        }

        /// Reads what [`tiles`] wrote onto a flat map of `grid` at `z0`.
        pub fn tiles(&mut self, grid: Grid, z0: f64) -> Result<HeightMap> {
            let mut map = HeightMap::flat(grid, z0);
            let n = self.u64()?;
            if n > map.tile_count() as u64 {
                return Err(bad("more tiles than the grid has"));
            }
            let tile_bytes = TILE_BYTES as u64;
            if n.checked_mul(tile_bytes)
                .is_none_or(|b| b > (self.bytes.len() - self.pos) as u64)
            {
                return Err(bad("the tile count does not match the blob's size"));
            }
            let mut z = vec![0.0; TILE * TILE];
            let mut cut = vec![0u64; HeightMap::MASK_WORDS];
            for _ in 0..n {
                let k = self.u64()? as usize;
                for x in z.iter_mut() {
                    *x = self.f64()?;
                    if !x.is_finite() {
                        return Err(bad("non-finite height"));
                    }
                }
                for w in cut.iter_mut() {
                    *w = self.u64()?;
                }
                let bound = self.f64()?;
                if !bound.is_finite() {
                    return Err(bad("non-finite height bound"));
                }
                map.load_tile(k, &z, &cut, bound)
                    .ok_or_else(|| bad("tile index out of range"))?;
            }
            Ok(map)
        }
    }
}
