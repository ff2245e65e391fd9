"""Joint-limit overrides name real joints and are ordered; named poses fit the arm and its limits."""
from __future__ import annotations

from ..diagnostics import codes
from ..formatting import angle, counted
from ..model import Design, ResolvedRobot
from .context import Context


def run(design: Design, ctx: Context) -> Design:
    for r in design.robots:
        if not isinstance(r, ResolvedRobot) or not r.units or any(not u.variant for u in r.units):
            continue
        joints = {f"joint_{i}": i for i in range(1, r.dof + 1)}
        for lim in r.limits:
            if lim.joint not in joints:
                ctx.report(codes.UNKNOWN_JOINT.at(lim.span, robot=r.name, name=lim.joint, dof=r.dof), r)
                continue
            if not lim.lower < lim.upper:
                ctx.report(
                    codes.LIMIT_ORDER.at(lim.span, joint=lim.joint, low=angle(lim.lower), high=angle(lim.upper)), r
                )
                continue
            hlo, hhi = r.hardware_range(joints[lim.joint])
            bounds = {"joint": lim.joint, "low": angle(lim.lower), "high": angle(lim.upper), "hlow": angle(hlo),
                      "hhigh": angle(hhi)}
            if lim.upper <= hlo or lim.lower >= hhi:
                ctx.report(codes.LIMIT_DISJOINT.at(lim.span, **bounds), r)
            elif lim.lower < hlo - 1e-12 or lim.upper > hhi + 1e-12:
                ctx.report(codes.LIMIT_EXCEEDS_HARDWARE.at(lim.span, **bounds), r)
        for pose in r.poses:
            if len(pose.q) != r.dof:
                ctx.report(codes.POSE_ARITY.at(pose.span, name=pose.name, got=counted(len(pose.q), "value"),
                                                   robot=r.name, dof=counted(r.dof, "joint")), r)
                continue
            for i, q in enumerate(pose.q, start=1):
                lo, hi = r.joint_range(i)
                if lo < hi and not (lo - 1e-12 <= q <= hi + 1e-12):
                    ctx.report(codes.POSE_OUT_OF_LIMITS.at(
                        pose.span, name=pose.name, joint=i, value=angle(q), low=angle(lo), high=angle(hi)), r)
    return design
