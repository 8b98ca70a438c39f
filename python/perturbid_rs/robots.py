"""Robots built into perturbid_rs (their URDFs are embedded in the extension module)."""

from __future__ import annotations

from ._core import Robot, a465_urdf

__all__ = ["a465", "a465_urdf", "VARIANTS"]

#: The A465 variants: "kinsheel2010" (fitted to the paper's Tables 2 and 3, the default) and
#: "physical" (CAD estimate, 16 kg moving mass).
VARIANTS = ("kinsheel2010", "physical")


def a465(variant: str = "kinsheel2010") -> Robot:
    """The CRS A465 arm of Kinsheel & Taha (2010): 6 revolute joints, frames parallel to the
    base at q = 0 (arm pointing up), gravity along -z.

    ``variant="kinsheel2010"`` is fitted to the paper's tables, physically consistent, with the
    motors' rotor inertia as each joint's armature; ``variant="kinsheel2010_lumped"`` is the
    first fit, with the rotor inertia lumped into each link (its links break the triangle
    inequality); ``variant="physical"`` is the CAD estimate. Raises ``ModelError`` for another
    name.
    """
    return Robot.builtin(f"a465:{variant}")
