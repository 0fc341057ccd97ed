"""The time-step kernel against a hand-written C Newmark of the same model (issue 16, item 4).

The C loop below is the same algorithm as ``geardyn.dynamics._kernel._advance`` for the paper's
configuration (6 DOF, affine load laws, no tooth errors or torque ripple, Newmark or HHT, model I
or model II with the centre-distance iteration, the same map interpolation on boundary-fitted
zones, a record row every step), written the way a careful C programmer would: one function,
fixed-size arrays on the stack, the same sanity checks per step (finite state,
deflection and bearing limits), ``-O2`` without ``-ffast-math`` (the kernel keeps
``fastmath=False``). It is compiled here with the machine's C compiler; where there is none the
rows say so and are skipped.

Before timing, both run the same 20,000 steps from the same state and their final states are
compared: the C loop is a baseline only if it computes the same thing (the relative difference
is printed in the row name).

Run: ``python benchmarks/run.py kernel_c`` (``--quick`` for fewer steps).
"""

from __future__ import annotations

import ctypes
import os
import shutil
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

from _common import Row, best_time

ROOT = Path(__file__).resolve().parents[1]

C_SOURCE = r"""
#include <math.h>

static double lookup(double theta, double dd, double dd0, double ddd, const double *pa,
                     const double *la_, double tm, long nc, long ns, long nd, const double *v)
{
    long i = 0, i2 = 0; double w = 0.0;
    if (nd > 1) {
        double x = (dd - dd0) / ddd;
        if (x < -1e-9 || x > (nd - 1) + 1e-9) return NAN;
        i = (long)floor(x);
        if (i < 0) i = 0;
        if (i > nd - 2) i = nd - 2;
        w = x - i;
        if (w < 0.0) w = 0.0;
        if (w > 1.0) w = 1.0;
        i2 = i + 1;
    }
    double a = pa[i] + w * (pa[i2] - pa[i]);
    double la = la_[i] + w * (la_[i2] - la_[i]);
    double period = nc * tm;
    double r = fmod(theta - a, period);
    if (r < 0.0) r += period;
    long c = (long)floor(r / tm);
    if (c >= nc) c = nc - 1;
    r -= c * tm;
    long zone; double f;
    if (la > 1e-12 * tm && r < la) { zone = 0; f = r / la; }
    else {
        zone = 1;
        double lb = tm - la;
        f = lb > 1e-12 * tm ? (r - la) / lb : 0.0;
        if (f < 0.0) f = 0.0;
    }
    if (f > 1.0) f = 1.0;
    double u = f * (ns - 1);
    long j = (long)floor(u);
    if (j > ns - 2) j = ns - 2;
    double t = u - j;
    long row = 2 * nc * ns, base = (2 * c + zone) * ns + j;
    double v1 = v[i * row + base] * (1.0 - t) + v[i * row + base + 1] * t;
    if (nd == 1) return v1;
    double v2 = v[i2 * row + base] * (1.0 - t) + v[i2 * row + base + 1] * t;
    return v1 * (1.0 - w) + v2 * w;
}

/* the map averaged over [theta - h, theta + h], split at the nearest handover (lookup_box) */
static double lookup_box(double theta, double h, double dd, double dd0, double ddd,
                         const double *pa, const double *la_, double tm, long nc, long ns,
                         long nd, const double *v)
{
    if (!(h > 0.0)) return lookup(theta, dd, dd0, ddd, pa, la_, tm, nc, ns, nd, v);
    double a, la;
    if (nd == 1) { a = pa[0]; la = la_[0]; }
    else {
        double x = (dd - dd0) / ddd;
        if (x < -1e-9 || x > (nd - 1) + 1e-9) return NAN;
        long i = (long)floor(x);
        if (i < 0) i = 0;
        if (i > nd - 2) i = nd - 2;
        double w = x - i;
        if (w < 0.0) w = 0.0;
        if (w > 1.0) w = 1.0;
        a = pa[i] + w * (pa[i + 1] - pa[i]);
        la = la_[i] + w * (la_[i + 1] - la_[i]);
    }
    double r = fmod(theta - a, tm);
    if (r < 0.0) r += tm;
    double tb = NAN, dist = h;
    if (r < dist) { tb = theta - r; dist = r; }
    if (tm - r < dist) { tb = theta + (tm - r); dist = tm - r; }
    if (la > 1e-12 * tm && fabs(r - la) < dist) tb = theta - (r - la);
    if (tb != tb) return lookup(theta, dd, dd0, ddd, pa, la_, tm, nc, ns, nd, v);
    double lo = theta - h, hi = theta + h;
    double vl = lookup(0.5 * (lo + tb), dd, dd0, ddd, pa, la_, tm, nc, ns, nd, v);
    double vr = lookup(0.5 * (tb + hi), dd, dd0, ddd, pa, la_, tm, nc, ns, nd, v);
    return ((tb - lo) * vl + (hi - tb) * vr) / (2.0 * h);
}

/* fp: dt beta gamma alpha qmb rsum t1t2 d0 tol rtol hstep sigma unorm;
   ip: model2 ev_start maxit sep n_steps window
   st: z[6] v[6] a[6] n_force; returns 0 or the failing step (1-based). */
long advance(const double *fp, const long *ip, const double *M, const double *Sinv,
             const double *SK, const double *SC, const double *sQ, const double *u,
             const double *g, double *st, long n0, double *out,
             double dd0, double ddd, const double *pa, const double *la, double tm, long nc,
             long ns, long nd, const double *kv)
{
    double dt = fp[0], beta = fp[1], gam = fp[2], al = fp[3], q = fp[4], rsum = fp[5];
    double t1t2 = fp[6], d0 = fp[7], tol = fp[8], rtol = fp[9], hstep = fp[10];
    double sigma = fp[11], unorm = fp[12], plim = fp[13], ylim = fp[14];
    int model2 = ip[0] != 0, ev_start = ip[1] != 0, sep = ip[3] != 0;
    long maxit = ip[2], n_steps = ip[4];
    int window = ip[5] != 0;
    double opa = 1.0 + al, bdt2 = beta * dt * dt, gdt = gam * dt, period = nc * tm;
    double *z = st, *v = st + 6, *a = st + 12;
    double xt[6], vt[6], w[6], an[6], ap[6];
    long n = n0;
    for (long s = 0; s < n_steps; ++s) {
        for (int i = 0; i < 6; ++i) {
            xt[i] = z[i] + dt * v[i] + dt * dt * (0.5 - beta) * a[i];
            vt[i] = v[i] + dt * (1.0 - gam) * a[i];
        }
        for (int i = 0; i < 6; ++i) {
            double acc = sQ[i];
            for (int k = 0; k < 6; ++k) acc -= SC[6 * i + k] * vt[k] + SK[6 * i + k] * xt[k];
            w[i] = opa * acc;
        }
        if (al != 0.0) {
            for (int i = 0; i < 6; ++i) {
                double acc = -sQ[i] + st[18] * u[i];
                for (int k = 0; k < 6; ++k) acc += SC[6 * i + k] * v[k] + SK[6 * i + k] * z[k];
                w[i] += al * acc;
            }
        }
        double gw = 0.0, pt = 0.0, pdt = 0.0;
        for (int i = 0; i < 6; ++i) { gw += g[i] * w[i]; pt += g[i] * xt[i]; pdt += g[i] * vt[i]; }
        double hh = (sep && pt + bdt2 * gw < 0.0) ? 0.0 : 1.0;
        double th, ype, yge;
        if (ev_start) { th = fmod(n * hstep, period) + z[2]; ype = z[1]; yge = z[3]; }
        else {
            th = fmod((n + 1) * hstep, period) + z[2] + dt * v[2] + 0.5 * dt * dt * a[2];
            ype = z[1] + dt * v[1] + 0.5 * dt * dt * a[1];
            yge = z[3] + dt * v[3] + 0.5 * dt * dt * a[3];
        }
        double hbox = window ? 0.5 * fabs(hstep + dt * v[2]) : 0.0;
        double b1 = d0;
        if (model2) { double e = t1t2 + yge - ype; b1 = sqrt(rsum * rsum + e * e); }
        long it = 0; double res = NAN, kk = 0.0, nf = 0.0, b2 = d0;
        double b2m1 = NAN, b2m2 = NAN, kfirst = 0.0, km1 = 0.0; int take_next = 0;
        for (;;) {
            kk = lookup_box(th, hbox, b1 - d0, dd0, ddd, pa, la, tm, nc, ns, nd, kv);
            if (kk != kk) return n + 1;
            if (it == 0) kfirst = kk;
            if (hh > 0.0) {
                double c = bdt2 * kk + gdt * q;
                nf = (kk * pt + q * pdt + c * gw) / (1.0 + opa * c * sigma);
            } else nf = 0.0;
            for (int i = 0; i < 6; ++i) an[i] = w[i] - opa * nf * u[i];
            double e = t1t2 + (xt[3] + bdt2 * an[3]) - (xt[1] + bdt2 * an[1]);
            b2 = sqrt(rsum * rsum + e * e);
            int conv = 1;
            if (model2) { res = fabs(b1 - b2); if (!(res < tol)) conv = 0; }
            if (it > 0) {
                double da = 0.0, aa = 0.0;
                for (int i = 0; i < 6; ++i)
                    for (int k = 0; k < 6; ++k) {
                        da += (an[i] - ap[i]) * M[6 * i + k] * (an[k] - ap[k]);
                        aa += an[i] * M[6 * i + k] * an[k];
                    }
                double sc = fmax(aa, (opa * nf * unorm) * (opa * nf * unorm));
                if (da > rtol * rtol * sc) conv = 0;
            }
            if (model2 && !conv) {
                if (take_next) conv = 1;
                else if (it >= 2 && fabs(b2 - b2m2) <= 1e-3 * tol && res >= tol) {
                    if (fabs(kk - kfirst) <= fabs(km1 - kfirst)) conv = 1; else take_next = 1;
                }
            }
            if (conv) break;
            if (it >= maxit) return n + 1;
            for (int i = 0; i < 6; ++i) ap[i] = an[i];
            b2m2 = b2m1; b2m1 = b2; km1 = kk;
            if (model2) b1 = b2;
            ++it;
        }
        for (int i = 0; i < 6; ++i) {
            z[i] = xt[i] + bdt2 * an[i]; v[i] = vt[i] + gdt * an[i]; a[i] = an[i];
        }
        st[18] = nf;
        ++n;
        double p = 0.0, tot = nf;
        for (int i = 0; i < 6; ++i) { p += g[i] * z[i]; tot += v[i] + a[i]; }
        if (!isfinite(tot + p) || fabs(p) > plim || fabs(z[1]) > ylim || fabs(z[3]) > ylim)
            return n;
        double *row = out + 20 * s;
        for (int i = 0; i < 6; ++i) { row[i] = z[i]; row[6 + i] = v[i]; }
        row[12] = nf; row[13] = b2 - d0; row[14] = kk; row[15] = hh; row[16] = (double)it;
        row[18] = res;
    }
    return 0;
}
"""


def _compile(tmp: Path):
    cc = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc")
    if cc is None:
        return None, "no C compiler on this machine"
    src, lib = tmp / "newmark.c", tmp / "newmark.so"
    src.write_text(C_SOURCE)
    r = subprocess.run([cc, "-O2", "-fPIC", "-shared", str(src), "-o", str(lib), "-lm"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        return None, f"{cc} failed: {r.stderr.strip()[:200]}"
    return ctypes.CDLL(str(lib)), cc


def _ptr(a: np.ndarray, kind=ctypes.c_double):
    return a.ctypes.data_as(ctypes.POINTER(kind))


class _CRunner:
    """Calls the C ``advance`` on a kernel setup (the arrays it needs, kept alive)."""

    def __init__(self, lib, setup):
        from geardyn.dynamics import _kernel as K

        fp, ip = setup.fp, setup.ip
        assert ip[K.IP_IN_NL] == 0 and ip[K.IP_OUT_NL] == 0, "affine laws only"
        assert fp[K.FP_RIP_AMP] == 0.0 and fp[K.FP_DRIVE_GAIN] == 0.0, "no ripple, no drive"
        assert setup.excitation[0][K.EI_ACTIVE] == 0, "no tooth errors"
        self.fp = np.array([fp[K.FP_DT], fp[K.FP_BETA], fp[K.FP_GAMMA], fp[K.FP_ALPHA],
                            fp[K.FP_QMB], fp[K.FP_RSUM], fp[K.FP_T1T2], fp[K.FP_D0],
                            fp[K.FP_TOL], fp[K.FP_RTOL], fp[K.FP_HSTEP], fp[K.FP_SIGMA],
                            fp[K.FP_UNORM], fp[K.FP_PLIM], fp[K.FP_YLIM]])
        self.ip = np.array([int(ip[K.IP_MODEL] == 2), int(ip[K.IP_EVAL] == 1),
                            int(ip[K.IP_MAXIT]), int(ip[K.IP_SEP]), 0,
                            int(ip[K.IP_WINDOW])], dtype=np.int64)
        m = setup.map_arrays
        self.mats = [np.ascontiguousarray(x, dtype=float) for x in
                     (setup.M, setup.Sinv, setup.SK, setup.SC, setup.sQ, setup.u, setup.g)]
        self.map = (float(m.dd0), float(m.ddd), np.ascontiguousarray(m.phase_a, float),
                    np.ascontiguousarray(m.length_a, float), float(m.mesh_angle),
                    int(m.n_cycles), int(m.n_seg), int(m.values.shape[0]),
                    np.ascontiguousarray(m.values, float))
        self.fn = lib.advance
        self.fn.restype = ctypes.c_long

    def run(self, st: np.ndarray, n0: int, n: int, out: np.ndarray) -> int:
        self.ip[4] = n
        dd0, ddd, pa, la, tm, nc, ns, nd, kv = self.map
        return self.fn(_ptr(self.fp), _ptr(self.ip, ctypes.c_long),
                       *[_ptr(x) for x in self.mats], _ptr(st), ctypes.c_long(n0), _ptr(out),
                       ctypes.c_double(dd0), ctypes.c_double(ddd), _ptr(pa), _ptr(la),
                       ctypes.c_double(tm), ctypes.c_long(nc), ctypes.c_long(ns),
                       ctypes.c_long(nd), _ptr(kv))


def _time_both(setup, static, crun: _CRunner, n: int) -> tuple[float, float]:
    """Best-of-3 time per step [us] of the kernel and of the C loop, ``n`` steps each."""
    from geardyn.dynamics import _kernel as K
    from geardyn.dynamics import initial_state, run_steps

    out_k = np.empty((n + 1, K.N_REC))
    out_c = np.empty((n, 20))

    def kernel():
        s, i = initial_state(setup, static.z)
        assert run_steps(setup, s, i, n, out=out_k)[0] == 0

    def hand_c():
        s, _ = initial_state(setup, static.z)
        assert crun.run(np.ascontiguousarray(s[:19].copy()), 0, n, out_c) == 0

    kernel()
    return (best_time(kernel, repeat=3) / n * 1e6, best_time(hand_c, repeat=3) / n * 1e6)


def run(quick: bool) -> list[Row]:
    sys.path.insert(0, str(ROOT))
    import geardyn
    from geardyn.dynamics import DynamicModel, initial_state, run_steps, static_equilibrium
    from geardyn.dynamics import _kernel as K
    from geardyn.dynamics.newmark import _setup_for_case
    from geardyn.stiffness import build_map

    with tempfile.TemporaryDirectory() as tmp:
        lib, cc = _compile(Path(tmp))
        if lib is None:
            return [Row(f"hand C Newmark: skipped ({cc})", float("nan"), "us/step")]
        case = geardyn.paper_case({"stiffness.method": "pem"})
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            smap = build_map(case, method="pem", cracked=True)
        n_check, n = 20_000, (50_000 if quick else 300_000)
        rows = []
        for which in ("I", "II"):
            dyn = DynamicModel.from_case(case, smap)
            static = static_equilibrium(dyn, smap, which=which)
            setup = _setup_for_case(case, dyn, smap, which, static)
            crun = _CRunner(lib, setup)
            # same computation? 20,000 steps from the static state, final states compared
            st_k, ist = initial_state(setup, static.z)
            out = np.empty((n_check + 1, K.N_REC))
            st_c = np.ascontiguousarray(st_k[:19].copy())
            assert run_steps(setup, st_k, ist, n_check, out=out)[0] == 0
            out_c = np.empty((n_check, 20))
            assert crun.run(st_c, 0, n_check, out_c) == 0
            scale = np.abs(st_k[:18]).max(axis=None)
            diff = float(np.max(np.abs(st_c[:18] - st_k[:18])) / scale)

            t_k, t_c = _time_both(setup, static, crun, n)
            rows.append(Row(f"model {which} step, numba kernel vs hand C ({Path(cc).name} -O2; "
                            f"final states agree to {diff:.1e} rel. after {n_check:,} steps)",
                            t_k, "us/step", "hand C Newmark", t_c,
                            "<= 1.5x the C step" if which == "II" else "(model II only)",
                            t_k <= 1.5 * t_c if which == "II" else None))
        return rows


if __name__ == "__main__":
    for r in run(quick="--quick" in sys.argv):
        print(f"{r.value:.4g} {r.unit}  baseline {r.baseline_value}  met={r.met}  {r.name}")
