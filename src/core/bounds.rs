// The allowed range of every numeric parameter, in one table.
//
// Plain Rust with no `use` and no inner attributes: `params.rs` includes it as
// a module, and `build.rs` `include!`s the same file to check that every
// `min`/`max` of modelDescription.xml mirrors it (the build fails on any
// difference). Change a bound here, then the XML attribute the build names.
//
// Each row: (FMI name, min, max), both inclusive. Integers are stored as f64
// (exact below 2^53). The reasons, in order:
// - disc: 20 mm to 2 m radius covers lab discs to the largest TBM discs with
//   a margin (17 in = 0.2159 m, 21 in = 0.27 m); tips 0.1 mm to 0.2 m;
//   flank angle 0 (flat side faces, the thesis) to 1.4 rad (80 deg; the
//   convexity rule in params.rs bounds it further, to 59 deg for the
//   thesis's tip), hub width 0.1 mm to 0.4 m (CCS rings are 50-100 mm wide);
// - rock: 0.1 MPa (chalk) to 1 GPa UCS, 10 kPa to 100 MPa BTS, C and spacing
//   as the CSM literature uses them with a factor 10-100 of margin;
// - face: coordinates within 10 km of the origin (the pose inputs allow 1000 km,
//   but a face that far out loses the 1 um cell to rounding);
// - numerics: below/above these the model either does unbounded work
//   (arc step, sweep step) or its results stop meaning anything (elastic
//   depth past 1 mm is not an elastic layer; psi <= -1 has no pressure
//   distribution);
// - chipping.pressureScale: a factor on the CSM pressure, 0.1 to 10 (its
//   calibrated default is 1.50; a factor of 10 either way is no longer a
//   calibration of the same law).
pub const PARAMETER_BOUNDS: &[(&str, f64, f64)] = &[
    ("cutter.radius", 0.02, 2.0),
    ("cutter.tipWidth", 1e-4, 0.2),
    ("cutter.tipRadius", 1e-4, 0.2),
    ("cutter.flankAngle", 0.0, 1.4),
    ("cutter.hubWidth", 1e-4, 0.4),
    ("rock.ucs", 1e5, 1e9),
    ("rock.bts", 1e4, 1e8),
    ("csm.C", 1e-3, 100.0),
    ("csm.spacing", 1e-3, 1.0),
    ("csm.psi", -0.9, 10.0),
    ("friction.mu", 0.0, 2.0),
    ("friction.vs", 1e-6, 10.0),
    ("rock.xMin", -1e4, 1e4),
    ("rock.xMax", -1e4, 1e4),
    ("rock.yMin", -1e4, 1e4),
    ("rock.yMax", -1e4, 1e4),
    ("rock.nx", 2.0, 1e8),
    ("rock.ny", 2.0, 1e8),
    ("rock.z0", -1e4, 1e4),
    ("rock.plasticFraction", 1e-3, 1.0),
    ("numerics.tipSlices", 3.0, 101.0),
    ("numerics.arcStepCells", 0.25, 100.0),
    ("numerics.ringStepCells", 0.01, 100.0),
    ("numerics.elasticDepth", 1e-9, 1e-3),
    ("numerics.pReg", 1e-8, 1e-2),
    ("numerics.sweepStep", 1e-6, 0.1),
    ("chipping.kappa", 1.0, 100.0),
    ("chipping.length", 1e-3, 1.0),
    ("chipping.lengthSpread", 0.0, 0.95),
    ("chipping.pressureScale", 0.1, 10.0),
];

// Rules between parameters (checked at fmi2ExitInitializationMode):

/// Smallest height-map cell \[m\] along x and y.
pub const MIN_CELL: f64 = 1e-6;
/// Largest number of height-map nodes, `rock.nx * rock.ny` (a 31.6 m square
/// face at 1 mm cells; the map is sparse, but its tile directory is dense
/// and a state snapshot copies it).
pub const MAX_NODES: f64 = 1e9;
/// Largest number of nodes under the disc's plan box, `(2R/dx + 3) (2R/dy + 3)`
/// clipped to the grid: what one cut or one cut probe may scan.
pub const MAX_DISC_NODES: f64 = 1e8;
/// Most steps of the contact-arc walk in one evaluation,
/// `numerics.tipSlices * pi R / (numerics.arcStepCells * min(dx, dy))`
/// (the default scene takes 1.5e3).
pub const MAX_ARC_STEPS: f64 = 2e6;
/// Smallest `numerics.sweepStep` in cells (`min(dx, dy)`): below it one
/// millimetre of travel costs more sub-steps than it can resolve.
pub const MIN_SWEEP_STEP_CELLS: f64 = 0.01;

// Work one call may do (checked before the call changes anything):

/// Sub-steps of one fmi2DoStep or one Model Exchange commit.
pub const MAX_SUBSTEPS_PER_CALL: f64 = 2e4;
/// Height-map nodes one fmi2DoStep or commit may scan (over all its sub-steps).
pub const MAX_NODE_VISITS_PER_CALL: f64 = 5e7;
/// What a node under a tilted disc (axle not horizontal) counts in that
/// budget: its lower boundary takes Newton steps (measured: a disc rolled
/// over by `wx` scanned ~2e6 nodes in 6 s, ~3 us a node, against ~50 ns a
/// node for an upright disc).
pub const TILTED_NODE_WEIGHT: f64 = 50.0;
/// Lines one surface file may have (written at fmi2Terminate, or read).
pub const MAX_SURFACE_LINES: f64 = 1e8;
/// Longest line of a surface file that is read, in bytes.
pub const MAX_SURFACE_LINE_BYTES: usize = 4096;
