use super::*;

fn small() -> HeightMap {
    HeightMap::flat(Grid::new(0.0, 1.0, 0.0, 2.0, 11, 21), 0.5)
}

/// A tile read back keeps the height bound it was written with: the cut
/// windows and the contact's arc walk start from that bound, so a bound
/// recomputed exactly on reading (tighter than one left by cuts) made a
/// state read back from bytes replay differently.
#[test]
fn a_tile_read_back_keeps_its_height_bound() {
    let g = Grid::new(0.0, 0.1, 0.0, 0.1, 101, 101);
    let mut m = HeightMap::flat(g, 0.5);
    m.lower_node(3, 3, 0.49);
    m.lower_node(4, 3, 0.47);
    for j in 0..TILE {
        for i in 0..TILE {
            m.lower_node(i, j, 0.4); // the whole tile cut: its bound stays 0.5
        }
    }
    let (k, z, cut) = m.touched_tiles().next().unwrap();
    let (z, cut) = (z.to_vec(), cut.to_vec());
    assert_eq!(m.tile_bound(k), 0.5);
    let mut back = HeightMap::flat(g, 0.5);
    back.load_tile(k, &z, &cut, m.tile_bound(k)).unwrap();
    assert_eq!(back.max_height(0, 31, 0, 31), m.max_height(0, 31, 0, 31));
    // a bound below the tile's own nodes is no bound: the nodes win
    back.load_tile(k, &z, &cut, 0.0).unwrap();
    assert_eq!(back.tile_bound(k), 0.4);
}

#[test]
fn a_row_lowers_as_its_nodes_do_and_rolls_back() {
    let g = Grid::new(0.0, 0.2, 0.0, 0.2, 201, 201);
    let mut m = HeightMap::flat(g, 0.5);
    m.set_node(40, 7, 0.45);
    let snapshot = m.clone(); // shares the tile: the row must unshare it
    let before = m.clone();
    let mut want = m.clone();
    // a row across three tiles (0, 1, 2; tile 2 untouched so far)
    let lower = |i: usize, z: f64| i.is_multiple_of(3).then_some(z - 1e-3 * i as f64);
    for i in 20..=70 {
        if let Some(z) = lower(i, want.node(i, 7)) {
            want.lower_node(i, 7, z);
        }
    }
    m.begin_undo();
    let mut i = 20;
    m.lower_row(7, 20, 70, |z| {
        let out = lower(i, z);
        i += 1;
        out
    });
    assert_eq!(i, 71, "every node seen once");
    let mut kept = m.clone();
    kept.commit_undo();
    assert!(kept == want && m.is_cut(69, 7) && !m.is_cut(70, 7));
    assert!(snapshot == before, "the snapshot's tile was not written");
    m.rollback();
    assert!(m == before);
}

#[test]
fn patches_read_and_cut_as_the_map_and_refuse_to_overlap() {
    let g = Grid::new(0.0, 0.2, 0.0, 0.2, 201, 201);
    let mut m = HeightMap::flat(g, 0.5);
    m.lower_node(40, 40, 0.4);
    let mut want = m.clone();
    let a = m.tile_rect(30, 70, 35, 50); // tiles 0..=2 x 1..=1
    let b = m.tile_rect(100, 140, 0, 120); // tiles 3..=4 x 0..=3
    assert!(!a.overlaps(&b) && a.overlaps(&m.tile_rect(64, 64, 40, 40)));
    assert!(m.patches(&[a, m.tile_rect(60, 99, 40, 40)]).is_none());
    let mut p = m.patches(&[b, a]).unwrap();
    assert_eq!(p[1].node(40, 40), 0.4);
    assert_eq!(p[1].node(70, 50), 0.5);
    p[1].lower_node(33, 47, 0.3);
    p[0].lower_node(140, 0, 0.2);
    want.lower_node(33, 47, 0.3);
    want.lower_node(140, 0, 0.2);
    assert!(m == want);
    assert!(m.is_cut(140, 0) && m.is_cut(33, 47));
}

/// After a refresh every tile's bound is the highest of its nodes on
/// the grid (an edge tile's nodes off it left out), whatever lowered
/// them: rows, single nodes, chips-like scattered writes, patches, set
/// nodes; before it, the bound is never below a node; a rollback puts
/// the bounds back with the nodes. Brute force over 300 rounds of
/// random writes on a map whose last tiles overhang the grid.
#[test]
fn refreshed_bounds_are_the_highest_node_of_each_tile() {
    let g = Grid::new(0.0, 0.1, 0.0, 0.07, 101, 71); // 4 x 3 tiles, the last ones partial
    let mut m = HeightMap::flat(g, 0.0);
    let mut u = crate::core::uniforms(0xb0b0);
    let exact = |m: &HeightMap, t: usize| {
        let (tj, ti) = (t / m.tiles_x, t % m.tiles_x);
        let mut top = NO_ROCK;
        for j in tj * TILE..((tj + 1) * TILE).min(g.ny) {
            for i in ti * TILE..((ti + 1) * TILE).min(g.nx) {
                top = top.max(m.node(i, j));
            }
        }
        top
    };
    let check_bounds = |m: &HeightMap, refreshed: bool| {
        for t in 0..m.tile_count() {
            if m.slot(t).is_some() {
                let (b, e) = (m.tile_bound(t), exact(m, t));
                assert!(b >= e, "tile {t}: bound {b} below node {e}");
                if refreshed {
                    assert_eq!(b, e, "tile {t}");
                }
            }
        }
    };
    let mut lowered = 0;
    for round in 0..300 {
        let before = m.clone();
        let undo = round % 7 == 3;
        if undo {
            m.begin_undo();
        }
        for _ in 0..(1 + (u() * 6.0) as usize) {
            let (i, j) = ((u() * g.nx as f64) as usize, (u() * g.ny as f64) as usize);
            let by = 1e-4 * (1.0 + 20.0 * u());
            match (u() * 4.0) as usize {
                // (whole rows, so that whole tiles come down)
                0 => m.lower_row(j, 0, g.nx - 1, |z| Some(z - by)),
                1 => m.lower_node(i, j, m.node(i, j) - by),
                2 => m.set_node(i, j, m.node(i, j) - by),
                _ if !undo => {
                    let rect = m.tile_rect(i, (i + 10).min(g.nx - 1), j, j);
                    let mut p = m.patches(&[rect]).unwrap();
                    p[0].lower_row(j, i, (i + 10).min(g.nx - 1), |z| Some(z - by));
                }
                _ => {}
            }
            lowered += 1;
        }
        check_bounds(&m, false);
        if undo {
            m.rollback();
            assert_eq!(m, before);
            for t in 0..m.tile_count() {
                assert_eq!(m.tile_bound(t), before.tile_bound(t));
            }
        } else {
            m.refresh_bounds();
            check_bounds(&m, true);
        }
    }
    // (the bounds came down: every tile's nodes were all lowered)
    assert!(lowered > 600);
    let down = (0..m.tile_count()).filter(|&t| m.tile_bound(t) < -1e-4);
    assert_eq!(down.count(), 4, "of 12");
}

/// The face's top bounds every node: cuts leave it, a node set above
/// it raises it, a loaded tile raises it to the tile's bound, and a new
/// lineage (nodes set through patches) finds it from the tiles again.
#[test]
fn the_top_bounds_every_node() {
    let g = Grid::new(0.0, 0.2, 0.0, 0.2, 201, 201);
    let mut m = HeightMap::flat(g, 0.5);
    assert_eq!(m.top(), 0.5);
    m.lower_node(10, 10, 0.4);
    m.lower_row(20, 0, 200, |z| Some(z - 0.1));
    assert_eq!(m.top(), 0.5);
    m.set_node(150, 10, 0.45);
    assert_eq!(m.top(), 0.5);
    m.set_node(150, 10, 0.6);
    assert_eq!(m.top(), 0.6);
    let k = m.touched_tiles().next().unwrap().0;
    let mut back = HeightMap::flat(g, 0.5);
    back.load_tile(k, &[0.2; TILE_NODES], &[0; MASK_WORDS], 0.7)
        .unwrap();
    assert_eq!(back.top(), 0.7);
    // through a patch: unknown to the map until the new lineage
    let mut p = HeightMap::flat(g, 0.5);
    let rect = p.tile_rect(100, 120, 100, 120);
    p.patches(&[rect]).unwrap()[0].set_node(110, 110, 0.9);
    assert_eq!(p.top(), 0.5);
    p.new_lineage();
    assert_eq!(p.top(), 0.9);
    let highest = (0..g.ny)
        .flat_map(|j| (0..g.nx).map(move |i| (i, j)))
        .map(|(i, j)| p.node(i, j))
        .fold(NO_ROCK, f64::max);
    assert_eq!(highest, 0.9);
}

/// The fast cell reads (the cut mask two nodes a shift, the tiles'
/// height bound) against node-by-node reads, on a map cut in a
/// scattered pattern across tile edges and mask words, with absent
/// tiles between.
#[test]
fn cell_masks_and_height_bounds_match_node_by_node_reads() {
    let g = Grid::new(0.0, 0.2, 0.0, 0.2, 201, 201);
    let mut m = HeightMap::flat(g, 0.5);
    for j in 0..120 {
        for i in 0..120 {
            // (a pattern with every cell shape: no tile fully cut, none
            // untouched in the block, tile (3, 3) left absent)
            if (i * 7 + j * 13) % 5 < 2 && !(96..128).contains(&i) {
                m.lower_node(i, j, 0.5 - 1e-3 * ((i + j) % 7) as f64);
            }
        }
    }
    m.set_node(150, 10, 0.6); // a raised node: the bound rises
    for j in 0..g.ny - 1 {
        for i in 0..g.nx - 1 {
            let each = m.is_cut(i, j) as u32
                | (m.is_cut(i + 1, j) as u32) << 1
                | (m.is_cut(i, j + 1) as u32) << 2
                | (m.is_cut(i + 1, j + 1) as u32) << 3;
            assert_eq!(m.cell_cut(i, j), each, "cell ({i}, {j})");
            assert_eq!(m.cell_nodes_cut(i, j).1, each, "cell ({i}, {j})");
        }
    }
    let highest = |i0: usize, i1: usize, j0: usize, j1: usize| {
        (j0..=j1)
            .flat_map(|j| (i0..=i1).map(move |i| (i, j)))
            .map(|(i, j)| m.node(i, j))
            .fold(NO_ROCK, f64::max)
    };
    for (i0, i1, j0, j1) in [
        (0, 31, 0, 31),
        (5, 130, 40, 70),
        (97, 127, 97, 127),
        (140, 200, 0, 20),
    ] {
        // (a bound: at least every node, and exact where no cut lowered
        // the tile's top)
        assert!(m.max_height(i0, i1, j0, j1) >= highest(i0, i1, j0, j1));
    }
    assert_eq!(m.max_height(97, 127, 97, 127), 0.5); // the absent tile reads z0
    assert_eq!(m.max_height(140, 200, 0, 20), 0.6);
    assert_eq!(m.max_height(0, 95, 0, 95), 0.5);
}

#[test]
fn flat_face_reads_z0_everywhere_and_nothing_outside() {
    let m = small();
    assert_eq!(m.height(0.37, 1.21), 0.5);
    assert_eq!(m.height(1.0, 2.0), 0.5);
    assert_eq!(m.height(-1e-9, 1.0), NO_ROCK);
    assert_eq!(m.height(0.5, 2.0 + 1e-9), NO_ROCK);
    assert_eq!(m.allocated_tiles(), 0);
}

#[test]
fn triangles_interpolate_a_plane_exactly_and_split_on_the_diagonal() {
    let mut m = small();
    // plane z = 2x - 3y + 1 is reproduced exactly by both triangles
    for i in 0..11 {
        for j in 0..21 {
            let (x, y) = m.grid().node_xy(i, j);
            m.set_node(i, j, 2.0 * x - 3.0 * y + 1.0);
        }
    }
    for &(x, y) in &[(0.33, 0.71), (0.36, 0.72), (0.99, 1.99), (0.0, 0.0)] {
        let p = m.point(x, y).unwrap();
        assert!((p.z - (2.0 * x - 3.0 * y + 1.0)).abs() < 1e-12);
        assert!((p.dzdx - 2.0).abs() < 1e-9 && (p.dzdy + 3.0).abs() < 1e-9);
    }
    // one raised node (1,1) of cell (0..1,0..1): lower triangle (fu > fv)
    // uses nodes (0,0),(1,0),(1,1); upper uses (0,0),(0,1),(1,1)
    let mut m = small();
    m.set_node(1, 0, 1.5); // only in the lower triangle
    let lower = m.height(0.08, 0.02); // fu = 0.8, fv = 0.2
    let upper = m.height(0.02, 0.08); // fu = 0.2, fv = 0.8
    assert!((lower - (0.5 + 1.0 * (0.8 - 0.2))).abs() < 1e-12, "{lower}");
    assert_eq!(upper, 0.5);
}

#[test]
fn clones_share_tiles_until_written() {
    let mut a = small();
    a.set_node(1, 1, 0.25);
    a.set_node(10, 20, 0.125); // same tile (the map is smaller than one tile)
    let b = a.clone();
    let shared = |m: &HeightMap, n: &HeightMap| {
        m.tiles()
            .zip(n.tiles())
            .filter(|(x, y)| matches!((x, y), (Some(x), Some(y)) if Arc::ptr_eq(&x.d, &y.d)))
            .count()
    };
    assert_eq!(shared(&a, &b), a.allocated_tiles());
    let mut c = b.clone();
    c.set_node(1, 1, 0.0);
    // the write copied the tile for c alone: a and b are unchanged and still share
    assert_eq!(a.node(1, 1), 0.25);
    assert_eq!(b.node(1, 1), 0.25);
    assert_eq!(c.node(1, 1), 0.0);
    assert_eq!(c.node(10, 20), 0.125);
    assert_eq!(shared(&a, &b), 1);
    assert_eq!(shared(&a, &c), 0);
    assert_ne!(a, c);
    assert_eq!(a, b);
    // the directory's rows are shared too, until a write unshares one
    let rows_shared = |m: &HeightMap, n: &HeightMap| {
        m.rows
            .iter()
            .zip(&n.rows)
            .filter(|(x, y)| Arc::ptr_eq(x, y))
            .count()
    };
    assert_eq!(rows_shared(&a, &b), a.rows.len());
    assert_eq!(rows_shared(&a, &c), a.rows.len() - 1);
}

#[test]
fn a_clone_shares_the_rows_of_tiles_until_a_write_and_a_read_only_walk_keeps_them() {
    // 4 x 3 tiles; rows of tiles 0 and 2 written
    let g = Grid::new(0.0, 0.127, 0.0, 0.095, 128, 96);
    let mut m = HeightMap::flat(g, 0.0);
    m.set_node(5, 5, -0.001);
    m.set_node(100, 70, -0.002);
    let snap = m.clone();
    let same = |a: &HeightMap, b: &HeightMap, r: usize| Arc::ptr_eq(&a.rows[r], &b.rows[r]);
    // a walk that lowers nothing leaves every row shared
    m.lower_row(5, 0, 127, |_| None);
    assert!((0..3).all(|r| same(&m, &snap, r)));
    // a write unshares its row only; the other rows stay shared
    m.lower_row(70, 90, 110, |z| (z > -0.0015).then_some(-0.0015));
    assert!(same(&m, &snap, 0) && same(&m, &snap, 1) && !same(&m, &snap, 2));
    assert_eq!(m.node(100, 70), -0.002);
    assert_eq!(m.node(95, 70), -0.0015);
    assert_eq!(snap.node(95, 70), 0.0);
    // patches unshare the rows they cover and write through them
    let mut p = m.clone();
    let rect = p.tile_rect(0, 40, 0, 40); // tiles 0..=1 x 0..=1
    let mut patches = p.patches(&[rect]).unwrap();
    patches[0].lower_row(33, 0, 40, |z| Some(z - 0.001));
    drop(patches);
    assert!(!same(&p, &m, 0) && !same(&p, &m, 1) && same(&p, &m, 2));
    assert_eq!(p.node(40, 33), -0.001);
    assert_eq!(m.node(40, 33), 0.0);
    // out of range rectangles are refused
    let bad = TileRect {
        ti: [3, 4],
        tj: [0, 0],
    };
    assert!(p.patches(&[bad]).is_none());
}

#[test]
fn writes_allocate_only_their_tile() {
    let mut m = HeightMap::flat(Grid::new(0.0, 10.0, 0.0, 10.0, 10_001, 10_001), 0.0);
    assert!(m.memory_bytes() < 2_000_000, "{}", m.memory_bytes());
    m.set_node(5000, 5000, -0.001);
    assert_eq!(m.allocated_tiles(), 1);
    assert_eq!(m.node(5000, 5000), -0.001);
    assert_eq!(m.node(5001, 5000), 0.0);
    assert!(m.max_height(4990, 5010, 4990, 5010) >= 0.0);
}
