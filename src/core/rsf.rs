//! Rock surface files (`.rsf`, thesis ch. 9.3): plain text, one node a line,
//! `L K x y z` (1-based node indices along x and y, coordinates in metres);
//! lines starting with `#` are comments. Loads with `numpy.loadtxt`.
//!
//! Two forms, both read back: *dense* lists every node (what a face of up to
//! [`DENSE_NODES`] nodes is written as), *sparse* lists only the nodes whose
//! height differs from the flat face's and says so in a comment line
//! `# sparse: unlisted nodes are at z0 = <z0>` (what a larger face is written
//! as, so that writing costs what the cut touched). The grid is in the
//! comment line `# grid nx=.. ny=.. x=[..] y=[..]` of both.
//!
//! Reading is bounded: the file must be a regular file (checked before it is
//! opened, so a FIFO cannot block), lines are read at most
//! [`MAX_SURFACE_LINE_BYTES`] long, at most [`MAX_SURFACE_LINES`] lines, and
//! memory grows with the nodes read, never with the declared grid.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::io::{BufRead, BufReader, BufWriter, Read, Write};
use std::path::Path;

use super::error::{KerfError, Result};
use super::heightmap::{Grid, HeightMap, TILE};
use super::params::{MAX_SURFACE_LINES, MAX_SURFACE_LINE_BYTES};

/// Faces of up to this many nodes are written dense, larger ones sparse.
pub const DENSE_NODES: usize = 1_000_000;

const SPARSE_TAG: &str = "# sparse: unlisted nodes are at z0 =";

fn err(file: &Path, line: usize, what: impl Into<String>) -> KerfError {
    KerfError::SurfaceFile {
        file: file.display().to_string(),
        line,
        what: what.into(),
    }
}

/// Checks that `path` is a regular file without opening it.
pub fn check_regular_file(path: &Path) -> Result<()> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => Ok(()),
        Ok(_) => Err(err(path, 0, "is not a regular file")),
        Err(e) => Err(err(path, 0, format!("cannot open: {e}"))),
    }
}

/// Reads one line of at most [`MAX_SURFACE_LINE_BYTES`] into `buf`
/// (cleared first); `Ok(false)` at the end of the file.
fn read_line(r: &mut impl BufRead, buf: &mut Vec<u8>, path: &Path, ln: usize) -> Result<bool> {
    buf.clear();
    let limit = MAX_SURFACE_LINE_BYTES as u64 + 1;
    let n = r
        .by_ref()
        .take(limit)
        .read_until(b'\n', buf)
        .map_err(|e| err(path, ln, format!("cannot read: {e}")))?;
    if n == 0 {
        return Ok(false);
    }
    if buf.last() != Some(&b'\n') && n as u64 == limit {
        return Err(err(
            path,
            ln,
            format!("line longer than {MAX_SURFACE_LINE_BYTES} bytes"),
        ));
    }
    Ok(true)
}

/// Reads a surface file that must describe the nodes of `grid`: every node
/// (dense), or, when it says it is sparse, the nodes that differ from `z0`.
pub fn read(path: &Path, grid: Grid, z0: f64) -> Result<HeightMap> {
    check_regular_file(path)?;
    let f = std::fs::File::open(path).map_err(|e| err(path, 0, format!("cannot open: {e}")))?;
    let mut reader = BufReader::new(f);
    let mut map = HeightMap::flat(grid, z0);
    let mut seen = Seen::new(&grid);
    let tol = node_tolerance(&grid);
    let mut count = 0usize;
    let mut sparse = false;
    let mut buf = Vec::new();
    let mut ln = 0usize;
    loop {
        ln += 1;
        if ln as f64 > MAX_SURFACE_LINES {
            return Err(err(
                path,
                ln,
                format!("more than {MAX_SURFACE_LINES:e} lines"),
            ));
        }
        if !read_line(&mut reader, &mut buf, path, ln)? {
            break;
        }
        let line = std::str::from_utf8(&buf).map_err(|_| err(path, ln, "not UTF-8 text"))?;
        let t = line.trim();
        if let Some(rest) = t.strip_prefix(SPARSE_TAG) {
            let base: f64 = rest.trim().parse().map_err(|_| {
                err(
                    path,
                    ln,
                    format!("bad sparse base height {:?}", rest.trim()),
                )
            })?;
            if base != z0 {
                return Err(err(
                    path,
                    ln,
                    format!("a sparse surface on z0 = {base}, but rock.z0 = {z0}"),
                ));
            }
            sparse = true;
            continue;
        }
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let (i, j, z) = node_line(t, &grid, tol, path, ln)?;
        if !seen.insert(i, j) {
            return Err(err(
                path,
                ln,
                format!("node ({}, {}) appears twice", i + 1, j + 1),
            ));
        }
        count += 1;
        if z != z0 {
            map.set_node(i, j, z);
        }
    }
    let want = grid.nx as f64 * grid.ny as f64;
    if !sparse && count as f64 != want {
        return Err(err(
            path,
            0,
            format!(
                "has {count} nodes, the declared grid {} x {} needs {} (or a `{SPARSE_TAG} ..` line)",
                grid.nx,
                grid.ny,
                grid.nx * grid.ny
            ),
        ));
    }
    Ok(map)
}

/// How far a node line's coordinates may lie from the grid's node: a
/// millionth of a cell, and the coordinates' own rounding.
fn node_tolerance(grid: &Grid) -> (f64, f64) {
    (
        1e-6 * grid.dx.max(1e-300) + 1e-9 * grid.x_min.abs().max(grid.x_max().abs()),
        1e-6 * grid.dy.max(1e-300) + 1e-9 * grid.y_min.abs().max(grid.y_max().abs()),
    )
}

/// A node line `L K x y z` of `grid`: its 0-based indices and height, the
/// indices whole and on the grid, the coordinates at that node within `tol`
/// ([`node_tolerance`]) and every number finite.
fn node_line(
    t: &str,
    grid: &Grid,
    (tol_x, tol_y): (f64, f64),
    path: &Path,
    ln: usize,
) -> Result<(usize, usize, f64)> {
    let fields: Vec<&str> = t.split_whitespace().collect();
    if fields.len() != 5 {
        return Err(err(
            path,
            ln,
            format!("expected 5 fields `L K x y z`, found {}", fields.len()),
        ));
    }
    let idx = |s: &str, name: &str, max: usize| -> Result<usize> {
        let v: f64 = s
            .parse()
            .map_err(|_| err(path, ln, format!("{name} = {s:?} is not a number")))?;
        if v.fract() != 0.0 || v < 1.0 || v > max as f64 {
            return Err(err(
                path,
                ln,
                format!("{name} = {s} is not a node index in 1..={max}"),
            ));
        }
        Ok(v as usize - 1)
    };
    let num = |s: &str, name: &str| -> Result<f64> {
        let v: f64 = s
            .parse()
            .map_err(|_| err(path, ln, format!("{name} = {s:?} is not a number")))?;
        if !v.is_finite() {
            return Err(err(path, ln, format!("{name} = {s} is not finite")));
        }
        Ok(v)
    };
    let i = idx(fields[0], "L", grid.nx)?;
    let j = idx(fields[1], "K", grid.ny)?;
    let (x, y, z) = (
        num(fields[2], "x")?,
        num(fields[3], "y")?,
        num(fields[4], "z")?,
    );
    let (gx, gy) = grid.node_xy(i, j);
    if (x - gx).abs() > tol_x || (y - gy).abs() > tol_y {
        return Err(err(
            path,
            ln,
            format!(
                "node ({}, {}) is at ({x}, {y}) but the declared grid puts it at ({gx}, {gy})",
                i + 1,
                j + 1
            ),
        ));
    }
    Ok((i, j, z))
}

/// The nodes a file has listed, a bit each, per tile of the map: grows with
/// the file, not with the grid.
struct Seen {
    tiles: HashMap<usize, [u64; TILE * TILE / 64]>,
    tiles_x: usize,
}

impl Seen {
    fn new(grid: &Grid) -> Self {
        Self {
            tiles: HashMap::new(),
            tiles_x: grid.nx.div_ceil(TILE),
        }
    }

    /// Marks node `(i, j)` seen; `false` if it was already.
    fn insert(&mut self, i: usize, j: usize) -> bool {
        let tile = (j / TILE) * self.tiles_x + i / TILE;
        let bit = (j % TILE) * TILE + i % TILE;
        let bits = self.tiles.entry(tile).or_insert([0; TILE * TILE / 64]);
        let (word, mask) = (bit / 64, 1u64 << (bit % 64));
        let new = bits[word] & mask == 0;
        bits[word] |= mask;
        new
    }
}

/// The nodes a sparse file lists: those whose height differs from the
/// flat face's, tile by tile.
fn changed_nodes(map: &HeightMap) -> impl Iterator<Item = (usize, usize, f64)> + '_ {
    let g = *map.grid();
    let z0 = map.base_height();
    let tiles_x = g.nx.div_ceil(TILE);
    map.touched_tiles().flat_map(move |(k, z, _)| {
        let (ti, tj) = ((k % tiles_x) * TILE, (k / tiles_x) * TILE);
        z.iter().enumerate().filter_map(move |(c, &zc)| {
            let (i, j) = (ti + c % TILE, tj + c / TILE);
            (i < g.nx && j < g.ny && zc != z0).then_some((i, j, zc))
        })
    })
}

/// Writes `map`: every node when the face has at most [`DENSE_NODES`],
/// else only the changed nodes (sparse). Refuses, before it creates the
/// file, to write more than [`MAX_SURFACE_LINES`] nodes.
pub fn write(path: &Path, map: &HeightMap) -> Result<()> {
    let g = *map.grid();
    let dense = g.nx * g.ny <= DENSE_NODES;
    let lines = if dense {
        g.nx * g.ny
    } else {
        changed_nodes(map).count()
    };
    if lines as f64 > MAX_SURFACE_LINES {
        return Err(err(
            path,
            0,
            format!(
                "refused, nothing written: {lines} changed nodes, more than the {MAX_SURFACE_LINES:e} one file may hold; use a smaller face or coarser cells"
            ),
        ));
    }
    // an existing path must be a regular file: opening a FIFO to write
    // blocks until someone reads it, a device never fills up
    if let Ok(m) = std::fs::metadata(path) {
        if !m.is_file() {
            return Err(err(path, 0, "exists and is not a regular file"));
        }
    }
    let f = std::fs::File::create(path).map_err(|e| err(path, 0, format!("cannot create: {e}")))?;
    let mut w = BufWriter::new(f);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# kerf rock surface: L K x y z (1-based node indices, metres)"
    );
    let _ = writeln!(
        s,
        "# grid nx={} ny={} x=[{}, {}] y=[{}, {}]",
        g.nx,
        g.ny,
        g.x_min,
        g.x_max(),
        g.y_min,
        g.y_max()
    );
    if !dense {
        let _ = writeln!(s, "{SPARSE_TAG} {}", map.base_height());
    }
    let io = |e: std::io::Error| err(path, 0, format!("cannot write: {e}"));
    w.write_all(s.as_bytes()).map_err(io)?;
    if dense {
        for j in 0..g.ny {
            s.clear();
            for i in 0..g.nx {
                let (x, y) = g.node_xy(i, j);
                let _ = writeln!(s, "{} {} {} {} {}", i + 1, j + 1, x, y, map.node(i, j));
            }
            w.write_all(s.as_bytes()).map_err(io)?;
        }
    } else {
        for (i, j, z) in changed_nodes(map) {
            s.clear();
            let (x, y) = g.node_xy(i, j);
            let _ = writeln!(s, "{} {} {} {} {}", i + 1, j + 1, x, y, z);
            w.write_all(s.as_bytes()).map_err(io)?;
        }
    }
    w.flush().map_err(io)
}
