"""`step/NAME.step`: an ISO 10303-21 AP214 (AUTOMOTIVE_DESIGN) assembly in millimetres.

One product per link with geometry, named exactly as the link, holding the link's exact
B-rep solid (`brep.py`); each is placed at its zero-pose FK pose in an assembly named as the
robot whose origin is `step_origin(robot)`, coloured with the link's material (XCAF colour
tool). Open CASCADE writes through a file only, so the emitter writes into a private
temporary folder and returns the bytes. The header is fixed (no timestamp, author or
machine) so that rebuilds are byte-identical.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from simkit import __version__
from simkit.derive import brep
from simkit.kitio import layout
from simkit.kitio.stepfile import canonical
from simkit.model.kinematics import forward
from simkit.model.robot import Robot

#: FILE_NAME fields that OCCT fills from the clock, the user and its own version.
ORIGINATING_SYSTEM = f"simkit {__version__}"
TIME_STAMP = "1970-01-01T00:00:00"


def step_origin(robot: Robot) -> str:
    """The assembly origin: `base_link` where the robot has one, else the root frame."""
    names = {link.name for link in robot.links}
    return "base_link" if "base_link" in names else robot.root


def zero_poses(robot: Robot) -> dict[str, np.ndarray]:
    """T_origin_link (m) at the zero pose (every joint at 0, a floating base at its start)."""
    poses = forward(robot)
    inv = np.linalg.inv(poses[step_origin(robot)])
    return {link.name: inv @ poses[link.name] for link in robot.links}


def _document(robot: Robot):
    """The XCAF document: the robot assembly with one coloured, named part per link."""
    from OCP.Quantity import Quantity_Color, Quantity_TypeOfColor
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDocStd import TDocStd_Document
    from OCP.TopLoc import TopLoc_Location
    from OCP.XCAFDoc import XCAFDoc_ColorType, XCAFDoc_DocumentTool

    doc = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
    XCAFDoc_DocumentTool.SetLengthUnit_s(doc, 0.001)  # document lengths are millimetres
    shapes = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    colours = XCAFDoc_DocumentTool.ColorTool_s(doc.Main())
    assembly = shapes.NewShape()
    TDataStd_Name.Set_s(assembly, TCollection_ExtendedString(robot.name))
    poses = zero_poses(robot)
    plans = robot.products.step_plans
    left_out = {entry["link"] for entry in robot.products.step_left_out}
    for link in robot.links:
        if link.name in left_out:
            continue
        plan = tuple(plans[link.name]) if link.name in plans else ()
        solid = brep.step_shape(link, plan)[0]
        if solid is None:
            continue
        part = shapes.AddShape(solid, False)
        TDataStd_Name.Set_s(part, TCollection_ExtendedString(link.name))
        r, g, b, _alpha = robot.material_rgba(link.material)
        colour = Quantity_Color(r, g, b, Quantity_TypeOfColor.Quantity_TOC_sRGB)
        colours.SetColor(part, colour, XCAFDoc_ColorType.XCAFDoc_ColorSurf)
        where = TopLoc_Location(brep.trsf(poses[link.name]))
        instance = shapes.AddComponent(assembly, part, where)
        TDataStd_Name.Set_s(instance, TCollection_ExtendedString(link.name))
    shapes.UpdateAssemblies()
    return doc


def _fix_header(writer, robot: Robot) -> None:
    """FILE_NAME without clock, user or machine: fixed strings only."""
    from OCP.APIHeaderSection import APIHeaderSection_MakeHeader
    from OCP.TCollection import TCollection_HAsciiString

    header = APIHeaderSection_MakeHeader(writer.ChangeWriter().Model())
    header.SetName(TCollection_HAsciiString(layout.step(robot.name)))
    header.SetTimeStamp(TCollection_HAsciiString(TIME_STAMP))
    header.SetAuthorValue(1, TCollection_HAsciiString(""))
    header.SetOrganizationValue(1, TCollection_HAsciiString(""))
    header.SetPreprocessorVersion(TCollection_HAsciiString(ORIGINATING_SYSTEM))
    header.SetOriginatingSystem(TCollection_HAsciiString(ORIGINATING_SYSTEM))
    header.SetAuthorisation(TCollection_HAsciiString(""))


def quiet() -> None:
    """Keep Open CASCADE's translator statistics off stdout (warnings and failures stay)."""
    from OCP.Message import Message, Message_Gravity

    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Warning)


def step_bytes(robot: Robot) -> bytes:
    """The STEP file's bytes (AP214, mm)."""
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.Interface import Interface_Static
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_StepModelType

    quiet()
    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    Interface_Static.SetIVal_s("write.surfacecurve.mode", 1)
    writer = STEPCAFControl_Writer()
    writer.SetColorMode(True)
    writer.SetNameMode(True)
    writer.SetLayerMode(False)
    writer.SetPropsMode(False)  # validation properties would add nothing a reader needs
    if not writer.Transfer(_document(robot), STEPControl_StepModelType.STEPControl_AsIs):
        raise RuntimeError(f"{robot.name}: Open CASCADE could not translate the STEP assembly")
    _fix_header(writer, robot)
    with tempfile.TemporaryDirectory(prefix="simkit-step-") as tmp:
        path = Path(tmp) / "out.step"
        if writer.Write(str(path)) != IFSelect_ReturnStatus.IFSelect_RetDone:
            raise RuntimeError(f"{robot.name}: Open CASCADE could not write the STEP file")
        text = path.read_text(encoding="utf-8").replace("\r\n", "\n")
    return canonical(text).encode("utf-8")


def emit(robot: Robot) -> dict[str, bytes]:
    """`step/NAME.step`."""
    return {layout.step(robot.name): step_bytes(robot)}
