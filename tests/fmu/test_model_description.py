"""modelDescription.xml against interface.md: identity, both interfaces, every
variable with its causality, type, unit and default; fmpy's validator."""

import math
import zipfile

import pytest
from fmpy.validation import validate_fmu

# name: (causality, type, unit, default start or None = not checked)
INPUTS = {n: ("input", "Real", u, 0.0) for n, u in [
    ("x", "m"), ("y", "m"), ("yaw", "rad"), ("pitch", "rad"), ("roll", "rad"),
    ("vx", "m/s"), ("vy", "m/s"), ("vz", "m/s"), ("wx", "rad/s"), ("wy", "rad/s"), ("wz", "rad/s")]}
INPUTS["z"] = ("input", "Real", "m", 0.2121)

OUTPUTS = {n: ("output", "Real", u, None) for n, u in [
    ("Fx", "N"), ("Fy", "N"), ("Fz", "N"), ("Mx", "N.m"), ("My", "N.m"), ("Mz", "N.m"),
    ("normalForce", "N"), ("rollingForce", "N"), ("sideForce", "N"),
    ("penetration", "m"), ("contactAngle", "rad"), ("excavatedVolume", "m3"),
    ("cuttingEnergy", "J"), ("specificEnergy", "J/m3")]}
OUTPUTS["inContact"] = ("output", "Boolean", None, None)

PARAMETERS = {
    "cutter.radius": ("parameter", "Real", "m", 0.2159),
    "cutter.tipWidth": ("parameter", "Real", "m", 0.013),
    "cutter.tipRadius": ("parameter", "Real", "m", 0.0127),
    "rock.ucs": ("parameter", "Real", "Pa", 158e6),
    "rock.bts": ("parameter", "Real", "Pa", 6.78e6),
    "csm.C": ("parameter", "Real", "1", 2.12),
    "csm.spacing": ("parameter", "Real", "m", 0.051),
    "csm.psi": ("parameter", "Real", "1", 0.0),
    "csm.variant": ("parameter", "Enumeration", None, 1),
    "friction.mu": ("parameter", "Real", "1", None),
    "friction.vs": ("parameter", "Real", "m/s", None),
    "rock.xMin": ("parameter", "Real", "m", None),
    "rock.xMax": ("parameter", "Real", "m", None),
    "rock.yMin": ("parameter", "Real", "m", None),
    "rock.yMax": ("parameter", "Real", "m", None),
    "rock.nx": ("parameter", "Integer", None, None),
    "rock.ny": ("parameter", "Integer", None, None),
    "rock.z0": ("parameter", "Real", "m", 0.0),
    "rock.initialSurface": ("parameter", "String", None, ""),
    "rock.finalSurface": ("parameter", "String", None, ""),
    "rock.plasticFraction": ("parameter", "Real", "1", 1.0),
    # numerical settings (README): names, types and units are fixed; their defaults
    # are the physics core's to tune, except the direction rule (1 = kerf's)
    "numerics.tipSlices": ("parameter", "Integer", None, None),
    "numerics.arcStepCells": ("parameter", "Real", "1", None),
    "numerics.ringStepCells": ("parameter", "Real", "1", None),
    "numerics.elasticDepth": ("parameter", "Real", "m", None),
    "numerics.pReg": ("parameter", "Real", "m", None),
    "numerics.sweepStep": ("parameter", "Real", "m", None),
    "numerics.directionRule": ("parameter", "Enumeration", None, 1),
}

CONTRACT = {**INPUTS, **OUTPUTS, **PARAMETERS}


def unit_of(v):
    return v.unit or (v.declaredType.unit if v.declaredType is not None else None)


def test_fmpy_validate_finds_no_problem(fmu_path):
    problems = validate_fmu(str(fmu_path))
    assert problems == [], "\n".join(problems)


def test_identity_and_capabilities(fmu, fmu_path):
    md = fmu.md
    assert md.fmiVersion == "2.0"
    assert md.variableNamingConvention == "structured"
    assert md.modelExchange is not None and md.coSimulation is not None, "needs both interfaces"
    for itf in (md.modelExchange, md.coSimulation):
        assert itf.modelIdentifier == "kerf"
        assert itf.canGetAndSetFMUstate is True
        assert itf.canSerializeFMUstate is True
        assert itf.canBeInstantiatedOnlyOncePerProcess is False
        assert itf.needsExecutionTool is False
    assert md.numberOfContinuousStates == 0
    with zipfile.ZipFile(fmu_path) as z:
        names = z.namelist()
    assert "modelDescription.xml" in names
    assert "binaries/linux64/kerf.so" in names


@pytest.mark.parametrize("name", sorted(CONTRACT))
def test_variable_matches_interface(fmu, name):
    causality, typ, unit, start = CONTRACT[name]
    assert name in fmu.vars, f"modelDescription.xml lacks {name}"
    v = fmu.vars[name]
    assert v.causality == causality, f"{name}: causality {v.causality}, interface.md says {causality}"
    assert v.type == typ, f"{name}: type {v.type}, expected {typ}"
    if typ == "Real":
        assert unit_of(v) == unit, f"{name}: unit {unit_of(v)!r}, interface.md says {unit!r}"
    if causality == "input":
        assert v.variability == "continuous"
    if start is not None:
        got = fmu.start(name)
        if isinstance(start, float):
            assert got is not None and math.isclose(got, start, rel_tol=1e-12, abs_tol=1e-300), \
                f"{name}: start {got}, expected {start}"
        else:
            assert got == start, f"{name}: start {got!r}, expected {start!r}"


def test_every_real_has_a_defined_unit(fmu):
    defined = {u.name for u in fmu.md.unitDefinitions}
    missing = [v.name for v in fmu.md.modelVariables if v.type == "Real" and unit_of(v) is None]
    assert not missing, f"Reals without unit: {missing}"
    undefined = sorted({unit_of(v) for v in fmu.md.modelVariables
                        if v.type == "Real" and unit_of(v) not in defined})
    assert not undefined, f"units used but not in <UnitDefinitions>: {undefined}"


def test_enumerations_have_the_documented_items(fmu):
    items = {int(i.value) for i in fmu.vars["csm.variant"].declaredType.items}
    assert items == {1, 2, 3, 4, 5}
    items = {int(i.value) for i in fmu.vars["numerics.directionRule"].declaredType.items}
    assert items == {1, 2}


def test_model_structure_lists_every_output(fmu):
    outs = {u.variable.name for u in fmu.md.outputs}
    assert set(OUTPUTS) <= outs, f"<Outputs> lacks {sorted(set(OUTPUTS) - outs)}"
    declared = {v.name for v in fmu.md.modelVariables if v.causality == "output"}
    assert outs == declared, "every output variable must appear once in <Outputs>"
