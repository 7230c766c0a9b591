#!/usr/bin/python3
"""Why lidar DBH comes out small: range noise lies along the beam, the circle fit measures it
across the surface (docs/trees.md, "Where the DBH error comes from"; BENCHMARK.md, session 41).

A 10 cm radius stem seen from one side (points over +-half_arc deg of it, from view directions
spread over `views` deg), range noise sigma along each beam, 300 points, 200 trials per row.
Three Tukey-weighted Gauss-Newton fits from the true circle, mean and sd of the radius error (mm):
  ortho: e = |p - c| - r, what src/trees/circle_fit.cpp's refineCircle does today;
  cosw:  the same, weighted by cos^2 of the angle between beam and surface normal;
  range: e = the distance along the point's beam from the circle's near-side intersection to the
         point (the errors-in-variables residual of a range measurement).
    /usr/bin/python3 bench/dbh_beam_noise.py
"""
import numpy as np

RADIUS_M = 0.1
rng = np.random.default_rng(2)


def residuals(points, beams, center, radius, mode):
    """Residuals, Jacobian rows (d/dcx, d/dcy, d/dr) and a per-point weight factor."""
    d = points - center
    dist = np.linalg.norm(d, axis=1)
    n = d / dist[:, None]
    if mode in ("ortho", "cosw"):
        J = np.c_[-n, -np.ones(len(points))]
        factor = np.ones(len(points)) if mode == "ortho" else np.clip(-(n * beams).sum(1), 0, 1) ** 2
        return dist - radius, J, factor
    # The beam's line p + s v meets the circle where |d + s v|^2 = r^2; s at the near side.
    b = (d * beams).sum(1)
    disc = b * b - (dist**2 - radius**2)
    hits = disc > 0
    s = -b - np.sqrt(np.where(hits, disc, 0.0))
    q = d + s[:, None] * beams  # centre to the intersection
    denom = (q * beams).sum(1)
    denom = np.where(np.abs(denom) < 1e-9, 1e-9, denom)
    # Implicit derivative of |d + s v|^2 = r^2: ds/dc = q / (q.v), ds/dr = r / (q.v).
    usable = hits & (np.abs(denom) > 0.2 * radius)  # not grazing (beyond ~78 deg)
    J = np.where(usable[:, None], np.c_[-q / denom[:, None], -radius / denom], 0.0)
    return np.where(usable, -s, 0.0), J, usable.astype(float)


def fit(points, beams, mode, iterations=60):
    center, radius, tukey = np.zeros(2), RADIUS_M, None
    for _ in range(iterations):
        e, J, factor = residuals(points, beams, center, radius, mode)
        if tukey is None:
            tukey = 4.685 * np.clip(1.4826 * np.median(np.abs(e[factor > 0])), 0.003, 0.025)
        u = e / tukey
        w = np.where(np.abs(u) < 1, (1 - u * u) ** 2, 0.0) * factor
        step = np.linalg.solve((J * w[:, None]).T @ J, -(J * w[:, None]).T @ e)
        center, radius = center + step[:2], radius + step[2]
        if np.linalg.norm(step) < 1e-9:
            break
    return radius


def trial(half_arc_deg, views_deg, sigma_m, mode, points=300, trials=200):
    errors_mm = []
    for _ in range(trials):
        view = np.deg2rad(rng.uniform(-views_deg / 2, views_deg / 2, points))
        phi = np.deg2rad(rng.uniform(-half_arc_deg, half_arc_deg, points)) + view
        beams = np.c_[np.sin(view), np.cos(view)]
        surface = np.c_[RADIUS_M * np.sin(phi), -RADIUS_M * np.cos(phi)]
        noisy = surface + rng.normal(0, sigma_m, points)[:, None] * beams
        errors_mm.append(1000 * (fit(noisy, beams, mode) - RADIUS_M))
    return np.mean(errors_mm), np.std(errors_mm)


print("| sigma cm | arc deg | views deg | ortho mm | cosw mm | range mm |")
print("|---|---|---|---|---|---|")
for sigma_m in (0.01, 0.015):
    for half_arc_deg, views_deg in ((90, 0), (70, 0), (80, 60), (60, 40)):
        cells = [f"{m:+.2f} (sd {s:.2f})" for m, s in
                 (trial(half_arc_deg, views_deg, sigma_m, mode) for mode in ("ortho", "cosw", "range"))]
        print(f"| {100 * sigma_m:.1f} | +-{half_arc_deg} | {views_deg} | " + " | ".join(cells) + " |")
