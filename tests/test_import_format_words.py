"""Import diagnostics use the source format's own words (issue 39, issue 38 item 8): an MJCF
import never says "URDF" (its armature, massless bodies, the base it bolts, the spec's
header), a URDF import keeps saying "URDF". Small handwritten models."""

from __future__ import annotations

from mjcf_models import arm, write
from simkit.importer import import_robot

# a joint without armature, a fixed base bolted to the world, a massless site body
MJCF = arm(extra="").replace("</body>\n    </body>", '<body name="tip"><site name="s"/></body>'
                              "</body>\n    </body>")  # fmt: skip
URDF = """<robot name="u">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>
"""


def test_an_mjcf_import_speaks_of_the_mjcf(tmp_path):
    done = import_robot(write(tmp_path / "src", MJCF, "arm.xml"), tmp_path / "out")
    text = done.spec_path.read_text()
    assert any("no armature in an MJCF" in line for line in done.lines), done.lines
    assert "Numbers are the MJCF's" in text and "root link to the world" in text
    assert "URDF" not in text and not any("URDF" in line for line in done.lines)


def test_a_urdf_import_speaks_of_the_urdf(tmp_path):
    done = import_robot(write(tmp_path / "src", URDF, "u.urdf"), tmp_path / "out")
    assert any("no armature in a URDF" in line for line in done.lines), done.lines
    assert any("no positive mass in the URDF" in line for line in done.lines), done.lines
    assert "Numbers are the URDF's" in done.spec_path.read_text()
