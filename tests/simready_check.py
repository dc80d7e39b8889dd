"""NVIDIA's SimReady Foundation validators (test dependency only) run on a kit's USD: the
Robot-Body profile's neutral features at its newest version and the Isaac tier's robot
features, each resolved to its requirement ids from the tiers' own feature files.

The tiers register their rules and requirements when usd-validation-nvidia loads its plugins;
their features and profiles are left to a SimReady loader that is not on PyPI, so this module
reads the feature JSON and profile TOML files that the tier wheels ship."""

from __future__ import annotations

import importlib
import json
import subprocess
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

PROFILE = "Robot-Body"
#: the profile's neutral features (no runtime suffix) and its required packaging features
NEUTRAL = "_STANDARD"
#: simready-foundation-tier-isaac: robot core, driven joints, composition, robot materials
ISAAC_TIER = (
    ("FET021_ROBOT_CORE_ISAAC", "0.2.0"),
    ("FET022_DRIVEN_JOINTS_ISAAC", "0.2.0"),
    ("FET100_BASE_ISAACSIM", "0.2.0"),
    ("FET023_ROBOT_MATERIALS", "0.1.0"),
)
#: the Isaac tier's features name their PhysX dependencies by the core tier's older ids
ALIASES = {
    ("FET022_DRIVEN_JOINTS_PHYSX", "0.2.0"): ("FET_022_PHYSX", "0.2.0"),
    ("FET003_BASE_PHYSX", "0.3.0"): ("FET_003_PHYSX", "0.3.0"),
}
#: a bare requirement id in a feature file takes this prefix (com.nvidia.usd.* ids are full)
PREFIX = "com.nvidia.simready."


@dataclass(frozen=True)
class Problem:
    """One failure or checker error: severity, requirement, rule, prim and message."""

    severity: str
    requirement: str
    rule: str
    at: str
    message: str

    def line(self) -> str:
        return f"{self.severity} {self.requirement} {self.rule} at {self.at}: {self.message}"


class _Schema(str):
    """A PhysX API schema as the validators use `pxr.PhysxSchema.<Class>`: its name (what
    `Usd.Prim.HasAPI` takes; the wheel's codeless classes are no TfTypes, which HasAPI would
    need) that also constructs, applies and gets like the wheel's class."""

    def __new__(cls, name: str, api: type | None):
        obj = super().__new__(cls, name)
        obj._api = api
        return obj

    def __call__(self, *args, **kwargs):
        return self._api(*args, **kwargs)

    def __getattr__(self, name: str):
        return getattr(self._api, name)


def register_physx_schema() -> None:
    """Make `pxr.PhysxSchema` importable: the validators import it from pxr, while the
    physx-usd-schemas wheel ships it as `physx_usd_schemas.PhysxSchema` (codeless classes;
    its plugins register on import). Its API classes become `_Schema` handles, and the
    validators' `PhysxJointAPI`, which the wheel's schema replaced by PhysxJointAxisAPI,
    names a schema that no prim has."""
    import types

    import pxr

    if "pxr.PhysxSchema" in sys.modules:
        return
    wheel = importlib.import_module("physx_usd_schemas.PhysxSchema")
    module = types.ModuleType("pxr.PhysxSchema", wheel.__doc__)
    for name in dir(wheel):
        value = getattr(wheel, name)
        api = getattr(value, "_schemaName", None)
        setattr(module, name, _Schema(api, value) if isinstance(api, str) else value)
    if not hasattr(module, "PhysxJointAPI"):
        module.PhysxJointAPI = _Schema("PhysxJointAPI", None)
    sys.modules["pxr.PhysxSchema"] = module
    pxr.PhysxSchema = module


#: core-tier validator modules that the Isaac tier registers again for the same requirements
CORE_FIRST = (
    "simready.foundation.tier_core.capabilities.isaac_sim.composition.validation",
    "simready.foundation.tier_core.capabilities.isaac_sim.robot_core.validation",
    "simready.foundation.tier_core.capabilities.isaac_sim.robot_materials.validation",
)


def prefer_core_tier() -> None:
    """Where both tiers register a validator for one requirement, use the core tier's: it is
    the newer release and reads local folders, while the Isaac tier's alpha lists folders and
    finds thumbnails only through Omniverse's omni.client (not on PyPI). Re-importing a
    module runs its registrations again, and the last registration wins."""
    register_physx_schema()
    import usd_validation_nvidia  # noqa: F401  (loads both tiers' plugins first)

    for name in CORE_FIRST:
        importlib.reload(importlib.import_module(name))


def _tier_dirs() -> list[Path]:
    from simready.foundation import tier_core, tier_isaac

    return [tier_core.tier.features_path, tier_isaac.tier.features_path]


def _features() -> dict[tuple[str, str], dict]:
    out = {}
    for folder in _tier_dirs():
        for path in sorted(folder.glob("*.json")):
            doc = json.loads(path.read_text())
            out[(doc["id"], doc["version"])] = doc
    return out


def profile_features(profile: str = PROFILE) -> tuple[str, list[tuple[str, str]]]:
    """(newest version, [(feature id, version)]) of the profile's neutral features, required
    and optional."""
    import tomllib  # Python 3.11+
    from simready.foundation import tier_core

    text = (tier_core.tier.profiles_path / "robot_body.toml").read_text()
    versions = tomllib.loads(text)[profile]
    newest = max(versions, key=lambda v: tuple(int(x) for x in v.split(".")))
    picked = []
    for entry in versions[newest]["features"]:
        ((fid, spec),) = ((k, v) for k, v in entry.items() if k != "optional")
        if fid.endswith(NEUTRAL):
            picked.append((fid, spec["version"]))
    return newest, picked


def requirement_ids(features: list[tuple[str, str]]) -> list[str]:
    """Every requirement of the features and of the features they depend on, full ids, in
    first-seen order; a dependency that no installed tier defines is an error."""
    known = _features()
    seen: set[tuple[str, str]] = set()
    out: list[str] = []
    pending = list(features)
    while pending:
        key = pending.pop(0)
        key = ALIASES.get(key, key)
        if key in seen:
            continue
        seen.add(key)
        if key not in known:
            raise KeyError(f"feature {key[0]}@{key[1]} is in no installed SimReady tier")
        doc = known[key]
        for req in doc["requirements"]:
            full = req if req.startswith("com.nvidia.") else PREFIX + req
            if full not in out:
                out.append(full)
        for dep in doc.get("dependencies") or []:
            ((fid, spec),) = dep.items()
            pending.append((fid, spec["version"]))
    return out


def validate(asset: Path, requirements: list[str]) -> list[Problem]:
    """Failures and errors of the requirements on the asset (a file), sorted. Runs in a fresh
    Python: schema plugins (PhysX, Isaac's robot schema) must register before pxr first reads
    its schema registry, which an earlier test in the same process has done."""
    proc = subprocess.run(
        [sys.executable, __file__, str(asset), *requirements],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    if proc.returncode != 0:
        raise RuntimeError(f"the SimReady validation did not run: {proc.stderr.strip()[-2000:]}")
    rows = [json.loads(line) for line in proc.stdout.splitlines() if line.startswith("{")]
    return [Problem(**row) for row in rows]


def _validate_here(asset: Path, requirements: list[str]) -> list[Problem]:
    register_physx_schema()
    prefer_core_tier()
    import usd.schema.isaac  # noqa: F401  (registers IsaacRobotAPI before any stage opens)
    from usd_validation_nvidia import IssueSeverity, RequirementsRegistry, ValidationEngine

    registry = RequirementsRegistry()
    engine = ValidationEngine(init_rules=False)
    for code in requirements:
        req = registry.find(code)
        if req is None:
            raise KeyError(f"requirement {code} is registered by no installed validator")
        engine.enable_requirement(req)
    out = []
    for issue in engine.validate(str(asset)).issues():
        if issue.severity not in (IssueSeverity.FAILURE, IssueSeverity.ERROR):
            continue
        at = issue.at
        where = ", ".join(a.as_str() for a in at) if isinstance(at, list | tuple) else at
        out.append(
            Problem(
                issue.severity.name,
                issue.requirement.code if issue.requirement else "-",
                issue.rule.__name__ if issue.rule else "-",
                str(where.as_str() if hasattr(where, "as_str") else where),
                " ".join(str(issue.message).split()),
            )
        )
    return sorted(out, key=lambda p: (p.requirement, p.at, p.message))


if __name__ == "__main__":
    for problem in _validate_here(Path(sys.argv[1]), sys.argv[2:]):
        print(json.dumps(asdict(problem)))
