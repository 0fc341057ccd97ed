r"""Analytical mesh stiffness by the potential energy method (PEM), healthy and with a root crack.

Each tooth is a non-uniform cantilever on an elastic gear body. A unit load ``F`` acts at the
contact point along the line of action (LOA); it stores the energies ``U = F^2 / (2 k)`` of

* Hertzian contact (Yang & Lin 1987): :func:`hertz_compliance`,
* bending, shear and axial compression of the tooth (Yang & Lin 1987; Tian 2004; Wu, Zuo & Parey
  2008; Ma, Song, Pang & Wen 2014 for the trochoid fillet): :func:`bending_compliance`,
  :func:`shear_compliance`, :func:`axial_compression_compliance`,
* the fillet-foundation (gear body) deflection (Sainsot, Velex & Duverger 2004):
  :func:`foundation_compliance`,

so that one tooth pair has the stiffness (all compliances in m/N)

.. math:: \frac{1}{k_{pair}} = \frac{1}{k_h} + \sum_{i=1,2}\left(\frac{1}{k_{b,i}}
          + \frac{1}{k_{s,i}} + \frac{1}{k_{a,i}} + \frac{1}{k_{f,i}}\right)

and the mesh stiffness along the LOA is ``k_mb = sum_j k_pair,j`` over the pairs in contact, with
load sharing ratio ``k_pair,j / k_mb`` (equal deflection of every pair, no coupling between the
foundations of adjacent teeth; trap T13 of ``docs/verification/stiffness.md``).

The exact tooth
---------------
The tooth section is taken from the rack-generated outline of :class:`geardyn.geometry.Gear`: the
involute above the form circle and the trochoidal fillet below it, down to the root circle at the
half-angle ``theta_f`` (``Gear.root_half_angle``). Integration along the tooth centreline starts
at the root chord ``y_0 = r_f cos(theta_f)``, where the Sainsot foundation takes over. This is
correct whether the root circle lies inside or outside the base circle. ``model="classic"`` gives
the textbook variant instead (involute from the base circle plus the root rectangle of Wan et al.
2014 / Ma et al. 2015 when ``r_f < r_b``, or the involute truncated at ``r_f``), for comparison with
published codes.

With the load point on the involute at roll angle ``phi`` (``phi = s / r_b``, ``s`` the distance
of the contact point from the tangency point along the LOA), the load makes the angle
``alpha_1 = phi - alpha_2`` with the normal to the tooth centreline, and its line crosses the
centreline at ``r_b / cos(alpha_1)`` from the centre. The moment per unit load about the section
at centreline height ``y`` is therefore

.. math:: \hat M(y) = \cos\alpha_1 (y_F - y) - h_F \sin\alpha_1 = r_b - y\cos\alpha_1 ,

and with the section width ``w(y)`` (``2 h(y)`` for a healthy tooth), ``A = w L``,
``I = w^3 L / 12`` and ``G = E / (2 (1 + nu))``:

.. math::
   \frac{1}{k_b} = \int_{y_0}^{y_F} \frac{12 \hat M^2}{E L w^3}\,dy, \quad
   \frac{1}{k_s} = \int_{y_0}^{y_F} \frac{2.4 (1+\nu)\cos^2\alpha_1}{E L w}\,dy, \quad
   \frac{1}{k_a} = \int_{y_0}^{y_F} \frac{\sin^2\alpha_1}{E L w}\,dy .

(For ``w = 2h`` these are the integrands of Tian 2004 and Chen & Shao 2011.) The centre distance
does not enter: it only moves the contact points along the operating LOA (``docs/verification/stiffness.md``
section 2.1), so each tooth's compliance is computed once against its roll angle on a fine table
and ``K(theta, d)`` is evaluated from the table for any ``d`` (no closed forms of Tian for
``alpha_1(theta)``, which assume the standard centre distance; trap T7).

The root crack
--------------
:class:`ToothCrack`: a straight crack of length ``depth`` (``q``) on one tooth of the pinion or
the gear. Angle convention (stated explicitly, trap T18): ``angle`` (``upsilon``) is the angle
between the crack and the tooth centreline; the crack runs from its mouth into the tooth and
towards the root, so its tip is ``q sin(upsilon)`` nearer the centreline and ``q cos(upsilon)``
lower than the mouth. The mouth is on the loaded (tension) side, at the fillet point where the
tangent makes 30 deg with the centreline (the critical section of ISO 6336-3, where root cracks
start); :func:`crack_geometry` gives the points so the finite-element route uses the same crack.
Above the crack tip, the material beyond a *limit line* carries no load:

* ``limit_line="parallel"``: the line through the tip parallel to the centreline (Tian 2004;
  Chen & Shao 2011), ``w = h + min(h, h_q)``; the tip must stay on the loaded side of the
  centreline (their "case 1"; the crossing case 2 is not modelled and raises InputError);
* ``limit_line="tip"``: the straight line from the crack tip to the tip corner of the cracked
  flank (Mohammed, Rantatalo & Aidanpaa 2013), which FE favours for large cracks; ``w = h + min(h,
  line(y))``. The tip line is meant to remove *less* material than the parallel one, so when the
  tip corner is nearer the centreline than the crack tip (shallow cracks: ``h_q`` above the tip
  half-thickness; the paper's 5 mm crack on this stubby 23-tooth pinion is such a case) the two
  lines coincide.

The parallel line therefore gives the larger (or equal) loss of stiffness (trap T18). Both keep the
section's moment arm about the tooth centreline (the shift of the neutral axis is neglected, as in
the cited papers). The crack changes neither the Hertz nor the foundation term; a crack tip below
the root chord ``y_0`` acts only through the beam sections above ``y_0``.

Modules
-------
One module per term family, each citing its source: :mod:`.hertz` (Yang & Lin 1987),
:mod:`.beam` (bending, shear, axial; Tian 2004), :mod:`.foundation` (Sainsot et al. 2004 and the
root half-angle choices), :mod:`.section` and :mod:`.profile` (the tooth section: trochoid fillet
of Ma et al. 2014, involute), :mod:`.crack` (crack geometry and limit lines), :mod:`.tooth` (one
tooth's total), :mod:`.body` (gear-body torsion), :mod:`.model` (:class:`PEMModel`, the pair and
the mesh) and :mod:`.mesh_map` (:func:`pem_map`). Import from ``geardyn.stiffness.pem``.

References
----------
Yang, D. C. H. & Lin, J. Y. (1987). Hertzian damping, tooth friction and bending elasticity in
gear impact dynamics. J. Mech. Transm. Autom. Des. 109:189-196.
Tian, X. (2004). Dynamic simulation for system response of gearbox including localized gear
faults. MSc thesis, University of Alberta.
Wu, S., Zuo, M. J. & Parey, A. (2008). Simulation of spur gear dynamics and estimation of fault
growth. J. Sound Vib. 317:608-624.
Sainsot, P., Velex, P. & Duverger, O. (2004). Contribution of gear body to tooth deflections - a
new bidimensional analytical formula. J. Mech. Des. 126:748-752.
Chen, Z. & Shao, Y. (2011). Dynamic simulation of spur gear with tooth root crack propagating
along tooth width and crack depth. Eng. Fail. Anal. 18:2149-2164.
Mohammed, O. D., Rantatalo, M. & Aidanpaa, J.-O. (2013). Improved method for calculating the
time-varying mesh stiffness of a spur gear pair with tooth crack. Eng. Fail. Anal. 34:235-251.
Ma, H., Song, R., Pang, X. & Wen, B. (2014). Time-varying mesh stiffness calculation of cracked
spur gears. Eng. Fail. Anal. 44:179-194.
Wan, Z., Cao, H., Zi, Y., He, W. & He, Z. (2014). An improved time-varying mesh stiffness
algorithm and dynamic modeling of gear-rotor system with tooth root crack. Eng. Fail. Anal.
42:157-177.
ISO 6336-3:2019, Calculation of load capacity of spur and helical gears - Part 3: tooth bending
strength (30 deg tangent critical section).
"""

from __future__ import annotations

from .beam import axial_compression_compliance, bending_compliance, shear_compliance
from .body import body_torsion_compliance
from .crack import CrackGeometry, ToothCrack, crack_geometry
from .foundation import (
    SAINSOT_RANGE,
    SAINSOT_TABLE,
    SainsotRangeWarning,
    foundation_compliance,
    sainsot_coefficients,
    sainsot_validity,
)
from .hertz import hertz_compliance
from .mesh_map import CITATIONS, pem_map
from .model import N_TABLE, PEMModel
from .section import N_GAUSS, ToothSection
from .tooth import tooth_compliance, tooth_compliance_quad

__all__ = [
    "ToothCrack",
    "CrackGeometry",
    "ToothSection",
    "PEMModel",
    "SainsotRangeWarning",
    "hertz_compliance",
    "bending_compliance",
    "shear_compliance",
    "axial_compression_compliance",
    "foundation_compliance",
    "sainsot_coefficients",
    "sainsot_validity",
    "crack_geometry",
    "tooth_compliance",
    "tooth_compliance_quad",
    "pem_map",
    "body_torsion_compliance",
    "CITATIONS",
    "N_GAUSS",
    "N_TABLE",
    "SAINSOT_RANGE",
    "SAINSOT_TABLE",
]
