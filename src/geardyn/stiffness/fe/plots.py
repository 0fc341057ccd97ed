"""Figures of the FE model: the meshed tooth with its crack (returns matplotlib Figures, no pyplot
state)."""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from .mesh import BodyMesh, build_body_mesh

__all__ = ["plot_body_mesh", "draw_mesh"]


def draw_mesh(ax, mesh: BodyMesh, window: tuple[float, float, float, float], *,
              displacement: np.ndarray | None = None, scale: float = 0.0,
              linewidth: float = 0.25) -> None:
    """Draw the triangles of ``mesh`` inside ``window = (x0, x1, y0, y1)`` [m] on ``ax`` in mm,
    the loaded flanks in blue and the crack faces in red.

    Parameters
    ----------
    displacement : ndarray, shape (2, n_nodes), optional
        Vertex displacements [m] drawn magnified by ``scale``.
    """
    p = mesh.p if displacement is None else mesh.p + scale * displacement
    x0, x1, y0, y1 = window
    cent = mesh.p[:, mesh.t].mean(axis=1)
    pad = 0.1 * max(x1 - x0, y1 - y0)
    sel = (cent[0] > x0 - pad) & (cent[0] < x1 + pad) & (cent[1] > y0 - pad) & (cent[1] < y1 + pad)
    ax.triplot(p[0] * 1e3, p[1] * 1e3, mesh.t[:, sel].T, color="0.35", lw=linewidth)
    for name, seg in mesh.edges.items():
        if name.startswith("flank"):
            colour, lw = "tab:blue", 1.2
        elif name.startswith("crack"):
            colour, lw = "tab:red", 1.6
        else:
            continue
        xs = np.stack([p[0, seg[0]], p[0, seg[1]], np.full(seg.shape[1], np.nan)]).T.ravel()
        ys = np.stack([p[1, seg[0]], p[1, seg[1]], np.full(seg.shape[1], np.nan)]).T.ravel()
        ax.plot(xs * 1e3, ys * 1e3, color=colour, lw=lw)
    ax.set_xlim(x0 * 1e3, x1 * 1e3)
    ax.set_ylim(y0 * 1e3, y1 * 1e3)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")


def plot_body_mesh(case, *, cracked: bool = True, zoom: bool = True,
                   opening: bool = False) -> Figure:
    """The FE mesh of the pinion (or the cracked gear) around the cracked/loaded tooth.

    Parameters
    ----------
    case : geardyn.config.Case
    cracked : bool
        Mesh the case's crack, if enabled.
    zoom : bool
        Add a panel zoomed on the crack (or on the loaded flank's root).
    opening : bool
        Draw the zoom deformed under a Hertzian patch load at the pitch point of the cracked
        tooth, magnified, to show the crack faces opening (one FE solve).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from .model import FESettings, _crack_of
    from .solve import ElasticBody, ElasticMaterial

    pair = case.gear_pair()
    crack = _crack_of(case, cracked)
    gear = pair.pinion if crack is None or case.crack.gear == "pinion" else pair.gear
    settings = FESettings.from_case(case)
    mesh = build_body_mesh(gear, settings.mesh_settings(), crack)
    m = gear.module
    half = 1.6 * math.pi / gear.teeth * gear.tip_radius
    fig = Figure(figsize=(11, 5.2) if zoom else (6, 5.2), layout="constrained")
    axes = fig.subplots(1, 2 if zoom else 1, squeeze=False)[0]
    draw_mesh(axes[0], mesh, (-half, half, gear.root_radius - 3.5 * m, gear.tip_radius + 0.3 * m))
    which = "cracked " if crack is not None else ""
    name = "pinion" if gear is pair.pinion else "gear"
    axes[0].set_title(f"{which}{name} tooth: {mesh.n_triangles} triangles (whole gear),\n"
                      f"P2, plane {settings.plane}", fontsize="medium")
    if zoom:
        if crack is not None:
            c = 0.5 * (mesh.crack_mouth + mesh.crack_tip)
            r = 0.5 * crack.depth + 0.6 * m
        else:  # where the loaded (left) flank meets the fillet, at the form circle
            rf = max(gear.form_radius, gear.base_radius)
            half_angle = 0.5 * gear.thickness_at(rf) / rf
            c = np.array([-rf * math.sin(half_angle), rf * math.cos(half_angle) - 0.3 * m])
            r = 0.9 * m
        disp = None
        scale = 0.0
        if opening:
            body = ElasticBody(mesh, ElasticMaterial(case.material.youngs_modulus,
                                                     case.material.poisson_ratio,
                                                     settings.plane))
            u = math.sqrt(gear.pitch_radius ** 2 - gear.base_radius ** 2)
            load = body.patch_loads(0, np.array([u]), settings.half_width)[:, 0]
            load *= settings.torque / gear.base_radius / case.pair.face_width
            x = body.solve(load)
            disp = np.vstack([x[body.dof_basis.nodal_dofs[0]], x[body.dof_basis.nodal_dofs[1]]])
            scale = 0.05 * r / max(np.max(np.hypot(*disp)), 1e-30)
        draw_mesh(axes[1], mesh, (c[0] - r, c[0] + r, c[1] - r, c[1] + r), displacement=disp,
                  scale=scale, linewidth=0.35)
        if crack is not None:
            tip = mesh.crack_tip * 1e3
            axes[1].plot(tip[0], tip[1], "o", ms=5, mfc="none", color="tab:red")
            title = (f"{crack.depth * 1e3:g} mm root crack at {math.degrees(crack.angle):g} deg:\n"
                     "duplicated nodes, free faces")
            if opening:
                title += f"\n(deformed under {settings.torque:g} N m at the pitch point, " \
                         f"x{scale:.0f})"
            axes[1].set_title(title, fontsize="medium")
        else:
            axes[1].set_title("loaded flank and fillet")
    return fig
