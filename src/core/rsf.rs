//! Rock surface files (`.rsf`, thesis ch. 9.3): plain text, one node a line,
//! `L K x y z` (1-based node indices along x and y, coordinates in metres);
//! lines starting with `#` are comments. Loads with `numpy.loadtxt`.

use std::fmt::Write as _;
use std::io::{BufRead, BufReader, BufWriter, Write};
use std::path::Path;

use super::error::{KerfError, Result};
use super::heightmap::{Grid, HeightMap};

fn err(file: &Path, line: usize, what: impl Into<String>) -> KerfError {
    KerfError::SurfaceFile {
        file: file.display().to_string(),
        line,
        what: what.into(),
    }
}

/// Reads a surface file that must describe exactly the nodes of `grid`.
pub fn read(path: &Path, grid: Grid, z0: f64) -> Result<HeightMap> {
    let f = std::fs::File::open(path).map_err(|e| err(path, 0, format!("cannot open: {e}")))?;
    let mut map = HeightMap::flat(grid, z0);
    let mut seen = vec![false; grid.nx * grid.ny];
    let mut count = 0usize;
    let tol_x = 1e-6 * grid.dx.max(1e-300) + 1e-9 * grid.x_min.abs().max(grid.x_max().abs());
    let tol_y = 1e-6 * grid.dy.max(1e-300) + 1e-9 * grid.y_min.abs().max(grid.y_max().abs());
    for (n, line) in BufReader::new(f).lines().enumerate() {
        let ln = n + 1;
        let line = line.map_err(|e| err(path, ln, format!("cannot read: {e}")))?;
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
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
        let k = j * grid.nx + i;
        if seen[k] {
            return Err(err(
                path,
                ln,
                format!("node ({}, {}) appears twice", i + 1, j + 1),
            ));
        }
        seen[k] = true;
        count += 1;
        if z != z0 {
            map.set_node(i, j, z);
        }
    }
    if count != grid.nx * grid.ny {
        return Err(err(
            path,
            0,
            format!(
                "has {count} nodes, the declared grid {} x {} needs {}",
                grid.nx,
                grid.ny,
                grid.nx * grid.ny
            ),
        ));
    }
    Ok(map)
}

/// Writes every node of `map`.
pub fn write(path: &Path, map: &HeightMap) -> Result<()> {
    let g = *map.grid();
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
    let io = |e: std::io::Error| err(path, 0, format!("cannot write: {e}"));
    w.write_all(s.as_bytes()).map_err(io)?;
    for j in 0..g.ny {
        s.clear();
        for i in 0..g.nx {
            let (x, y) = g.node_xy(i, j);
            let _ = writeln!(s, "{} {} {} {} {}", i + 1, j + 1, x, y, map.node(i, j));
        }
        w.write_all(s.as_bytes()).map_err(io)?;
    }
    w.flush().map_err(io)
}
