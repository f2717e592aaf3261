"""Helpers shared by the head drivers: the FMU's output names (Real outputs,
from modelDescription.xml), the input table of a CSV, ZOH lookup, and an
fmpy Co-Simulation slave set up from such a table."""
import csv
import xml.etree.ElementTree as ET
import zipfile

# the head's totals the drivers record, in this order (those the FMU has)
TOTALS = ["Fx", "Fy", "Fz", "Mx", "My", "Mz", "thrust", "torque", "excavatedVolume", "cuttingEnergy",
          "specificEnergy", "chippedVolume"]


def real_outputs(fmu):
    with zipfile.ZipFile(fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    names = []
    for sv in root.iter("ScalarVariable"):
        if sv.get("causality") == "output" and sv.find("Real") is not None:
            names.append(sv.get("name"))
    return names


def read_inputs(path):
    with open(path, newline="") as f:
        rd = csv.reader(f)
        head = next(rd)
        rows = [[float(x) for x in r] for r in rd if r]
    return head[1:], rows


def value_at(rows, t):
    """Row values (without time) of the last row with time <= t (+1e-12):
    the inputs at the start of a communication step (zero-order hold; exact
    for the head scenario, whose inputs are linear in t and sampled at every
    step)."""
    best = rows[0]
    for r in rows:
        if r[0] <= t + 1e-12:
            best = r
        else:
            break
    return best[1:]


def parse_starts(args):
    """NAME=VALUE arguments -> dict of floats."""
    d = {}
    for a in args:
        k, v = a.split("=", 1)
        d[k] = float(v)
    return d


def head_totals(fmu):
    """The names of TOTALS that `fmu` has as Real outputs, in TOTALS order."""
    have = set(real_outputs(fmu))
    return [n for n in TOTALS if n in have]


def run_args(argv):
    """`[stop=0.2] [h=1e-3] [NAME=VALUE ...]` of a driver's command line:
    (stop, h, start values)."""
    stop = float(argv[0]) if len(argv) > 0 else 0.2
    h = float(argv[1]) if len(argv) > 1 else 1e-3
    return stop, h, parse_starts(argv[2:])


def cs_slave(fmu, names, rows, starts=None):
    """An fmpy Co-Simulation slave of `fmu`, initialised with the start
    values `starts` (name -> value) and the first row of an input table
    (`read_inputs`'s names and rows): (slave, value reference by name).
    fmpy is imported here, so the drivers that do not need it need not
    have it."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    f = FMU2Slave(guid=md.guid, unzipDirectory=extract(fmu),
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName="h")
    f.instantiate()
    f.setupExperiment(startTime=0.0)
    f.enterInitializationMode()
    for k, v in (starts or {}).items():
        f.setReal([vr[k]], [float(v)])
    f.setReal([vr[x] for x in names], rows[0][1:])
    f.exitInitializationMode()
    return f, vr
