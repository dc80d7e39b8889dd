"""index.json's per-kit facts (simkit/publish/registry.py): the category comes from the
model's tree, the tool from the check's name, the licence from package.xml."""

from __future__ import annotations

from simkit.check.findings import Finding
from simkit.publish import registry


def _joint(name, parent, child, kind="revolute"):
    return {"name": name, "parent": parent, "child": child, "type": kind}


def _chain(prefix, root, n):
    links = [root] + [f"{prefix}{i}" for i in range(n)]
    return [_joint(f"{prefix}j{i}", links[i], links[i + 1]) for i in range(n)]


def test_a_fixed_serial_chain_is_an_arm_and_a_fork_is_branched():
    arm = {"joints": _chain("a", "base", 6)}
    assert registry.category(arm) == "arm" and registry.dof(arm) == 6
    fork = {"joints": _chain("l", "base", 3) + _chain("r", "base", 3)}
    assert registry.category(fork) == "branched"


def test_a_floating_base_with_two_limbs_is_legged_without_them_floating():
    legs = {
        "floating_base": {"child": "pelvis"},
        "joints": _chain("l", "pelvis", 3) + _chain("r", "pelvis", 3),
    }
    assert registry.category(legs) == "legged"
    rotors = {
        "floating_base": {"child": "body"},
        "joints": [_joint(f"rotor{i}", "body", f"prop{i}", "continuous") for i in range(4)],
    }
    assert registry.category(rotors) == "floating"  # four branches of one joint: no limbs


def test_a_fixed_joint_does_not_count_as_a_branch_or_a_degree_of_freedom():
    arm = {
        "joints": [*_chain("a", "base", 2), _joint("cam", "base", "camera", "fixed")],
        "fixed_joints": [{"name": "tcp", "parent": "a1", "child": "tool0"}],
    }
    assert registry.category(arm) == "arm" and registry.dof(arm) == 2


def test_checks_are_grouped_by_format_with_the_tool_that_loaded_them():
    findings = [
        Finding("urdf.yourdfpy", True, ""),
        Finding("urdf.compile", True, ""),
        Finding("usd.open", False, ""),
        Finding("nobody.knows", True, ""),
    ]
    groups = registry.checks(findings)
    assert groups["urdf"] == {"passed": 2, "total": 2, "tools": ["MuJoCo", "yourdfpy"]}
    assert groups["usd"] == {"passed": 0, "total": 1, "tools": ["pxr (OpenUSD)"]}
    assert groups["nobody"]["tools"] == ["simkit"]
    assert list(groups) == sorted(groups)


def test_licence_is_package_xml_s():
    xml = b'<package format="3"><name>x</name><license file="L">Apache-2.0</license></package>'
    assert registry.licence({"package.xml": xml}) == "Apache-2.0"
    assert registry.licence({}) is None
