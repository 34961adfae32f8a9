"""What the line study shows: seed 000's line as a session (belt, items, SCARAs picking), its
schedule and its sizing curves (throughput and miss rate against flow and number of arms, 95 %
band over the seeds). The demo writes them as ``sessions/line.pinarms``, ``html/line.html``,
``plots/line_schedule.png`` and ``plots/line_sizing.png``.

Belt speed is not swept here: the package's task maps hold seed 000's belt at 0.2 m/s only
(:func:`viz.line_plots.line_curve` sweeps it where maps for other speeds exist or may be built).
"""

from __future__ import annotations

from typing import Any

__all__ = ["line_views"]


def line_views(n_arms: int, rate: float = 60.0, *, seeds: tuple[int, ...] = (0, 1, 2), duration: float = 300.0,
               window: float = 20.0) -> tuple[Any, dict]:
    """(session, {plot name: writer(path)}) of ``n_arms`` SCARAs at ``rate`` bunches/min (module doc)."""
    from pinarms import viz
    from pinarms.optim.line import run_line
    from pinarms.studies.line import maps_for, scara_line
    from pinarms.viz.line_plots import line_curve, plot_line_schedule, plot_line_sizing

    n = max(1, int(n_arms))
    spec = scara_line(n, rate, seeds=seeds, duration=duration)
    result = run_line(spec, maps=maps_for(spec))
    f = result.figures
    session = viz.Session(title=f"seed 000 line: {n} SCARA(s), {rate:g} enoki bunches/min, "
                                f"belt {spec.belt.speed:g} m/s ({f.picks_per_minute:.1f} picks/min, miss {100 * f.miss_rate:.1f} %)")
    session.add_line(spec, result, duration=window)

    def sizing(path: Any) -> Any:
        flows = line_curve(lambda r: scara_line(n, r, seeds=seeds, duration=duration),
                           [rate * k for k in (0.5, 0.75, 1.0, 1.25, 1.5)], maps=maps_for)
        arms = line_curve(lambda k: scara_line(int(k), rate, seeds=seeds, duration=duration),
                          list(range(max(1, n - 2), n + 3)), maps=maps_for)
        return plot_line_sizing(path, {f"flow [bunches/min] ({n} arms)": flows, f"arms ({rate:g} bunches/min)": arms},
                                title=f"seed 000 line, belt {spec.belt.speed:g} m/s, rule {spec.rule.name}, "
                                      f"{len(seeds)} seeds × {duration:g} s")

    plots = {"schedule": lambda path: plot_line_schedule(path, result, window=(0.0, 60.0)), "sizing": sizing}
    return session, plots
