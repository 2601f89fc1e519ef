"""The statistics of a recovery map: Wilson score intervals for a recovery probability, the impulse where the
probability falls below a level (linear interpolation between grid points), and a bootstrap interval for it
over the push phases (a phase is the unit resampled: the map's question is how robust a controller is wherever
in the gait the push lands)."""
import math
import random

Z95 = 1.959963984540054  # the two-sided 95 % normal quantile


def wilson(k, n, z=Z95):
    """(low, high) of the Wilson score interval for k successes in n trials; (0, 1) for n = 0."""
    if n == 0:
        return 0.0, 1.0
    p = k / n
    denom = 1.0 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    return max(0.0, centre - half), min(1.0, centre + half)


def crossing(impulses, probs, level):
    """The impulse where the probability first falls below `level`, interpolated linearly between the last grid
    point at or above it and the first one below; the first impulse when it starts below; None when it never
    falls below (the grid ends first)."""
    for i, (x, p) in enumerate(zip(impulses, probs)):
        if p < level:
            if i == 0:
                return float(x)
            x0, p0 = impulses[i - 1], probs[i - 1]
            return float(x0 + (p0 - level) / (p0 - p) * (x - x0))
    return None


def curve(rows, impulses):
    """The recovery probability per impulse over `rows` ({impulse: recovered} per phase); an impulse a row did not
    run (its scan stopped below it after repeated failures) counts as failed."""
    n = len(rows)
    return [sum(1 for r in rows if r.get(i, False)) / n if n else 0.0 for i in impulses]


def bootstrap(rows, impulses, level, samples=2000, seed=1, alpha=0.05):
    """(low, high) percentile interval of crossing() over `samples` resamplings of the rows with replacement;
    a resampling whose curve never falls below `level` counts at the grid's end (+inf is not an impulse)."""
    if not rows:
        return None, None
    rng = random.Random(seed)
    values = []
    for _ in range(samples):
        pick = [rows[rng.randrange(len(rows))] for _ in rows]
        c = crossing(impulses, curve(pick, impulses), level)
        values.append(impulses[-1] if c is None else c)
    values.sort()
    lo = values[int(math.floor(alpha / 2 * (samples - 1)))]
    hi = values[int(math.ceil((1 - alpha / 2) * (samples - 1)))]
    return lo, hi
