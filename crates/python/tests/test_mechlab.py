"""The Python module against closed forms and the library's own checks:
each assertion could fail if the bindings were wrong (a parameter not
passed, a state's rows shuffled, an error's class or message lost)."""

import math
import os
import signal
import threading
import unittest

import numpy as np

import mechlab


class Models(unittest.TestCase):
    def test_the_catalogue_and_an_unknown_name(self):
        self.assertIn("kapitza", mechlab.models())
        with self.assertRaises(ValueError) as e:
            mechlab.model("no_such_model")
        self.assertIn("kapitza", str(e.exception))

    def test_parameters_by_name_with_their_ranges(self):
        m = mechlab.model("kapitza")
        self.assertEqual(m.parameters["A"], 1.5)
        self.assertEqual(m.ranges["eps"], "(0, inf)")
        self.assertEqual(m.values({"A": 2.0})[list(m.parameters).index("A")], 2.0)
        with self.assertRaises(ValueError) as e:
            m.values({"bogus": 1.0})
        self.assertIn("bogus", str(e.exception))
        with self.assertRaises(ValueError) as e:
            m.values({"eps": -1.0})
        self.assertIn("eps", str(e.exception))

    def test_derivations_as_text_and_latex(self):
        d = mechlab.model("kapitza").derivations
        self.assertGreater(len(d), 3)
        keys = [x.key for x in d]
        self.assertIn("hamiltonian", keys)
        self.assertTrue(d._repr_latex_().startswith("$$\\begin{aligned}"))
        self.assertTrue(d[0]._repr_latex_().startswith("$$"))


class Integration(unittest.TestCase):
    def test_uncoupled_henon_heiles_is_two_harmonic_oscillators(self):
        m = mechlab.model("henon_heiles")
        t = np.linspace(0.0, 20.0, 81)
        y0 = np.array([0.3, -0.2, 0.1, 0.4])  # x, y, p_x, p_y
        y = m.integrate(y0, t, tol=1e-12, params={"lambda": 0.0})
        self.assertEqual(y.shape, (81, 4))
        exact_x = y0[0] * np.cos(t) + y0[2] * np.sin(t)
        exact_py = -y0[1] * np.sin(t) + y0[3] * np.cos(t)
        self.assertLess(np.max(np.abs(y[:, 0] - exact_x)), 1e-9)
        self.assertLess(np.max(np.abs(y[:, 3] - exact_py)), 1e-9)

    def test_many_orbits_equal_each_run_alone(self):
        m = mechlab.model("kapitza")
        t = np.linspace(0.0, 3.0, 7)
        starts = np.array([[0.1, 0.0], [1.0, 0.5], [3.0, -0.2]])
        many = m.integrate_many(starts, t, params={"A": 2.0})
        self.assertEqual(many.states.shape, (3, 7, 2))
        self.assertEqual(many.failed, [])
        for k in range(3):
            alone = m.integrate(starts[k], t, params={"A": 2.0})
            np.testing.assert_array_equal(many.states[k], alone)

    def test_a_constrained_start_is_put_on_its_constraints(self):
        m = mechlab.model("four_bar")
        self.assertEqual(m.kind, "constrained")
        start = m.start()
        y = m.integrate(start, [0.0, 0.5, 1.0])
        np.testing.assert_allclose(y[0], start, atol=1e-12)
        # A start off the constraints is projected onto them, once for all.
        moved = m.integrate(start + 0.05, [0.0, 1.0])[0]
        self.assertGreater(np.max(np.abs(moved - start - 0.05)), 1e-3)
        np.testing.assert_allclose(m.integrate(moved, [0.0, 1.0])[0], moved, atol=1e-12)

    def test_bad_input_is_a_value_error_naming_it(self):
        m = mechlab.model("kapitza")
        with self.assertRaises(ValueError) as e:
            m.integrate([0.1, 0.0, 0.0], [0.0, 1.0])
        self.assertIn("3 components", str(e.exception))
        with self.assertRaises(ValueError):
            m.integrate([0.1, 0.0], [0.0, 1.0], tol=0.0)
        with self.assertRaises(ValueError):
            m.integrate([math.nan, 0.0], [0.0, 1.0])
        with self.assertRaises(mechlab.Refused):
            mechlab.model("painleve_klein").integrate([0.0] * 4, [0.0, 1.0])


class Analyses(unittest.TestCase):
    def test_kapitza_threshold_is_root_two(self):
        s = mechlab.model("kapitza").stability(samples=12)
        thresholds = [e.a_star for e in s.equilibria if e.a_star is not None]
        self.assertEqual(len(thresholds), 1)
        self.assertAlmostEqual(thresholds[0], math.sqrt(2.0), places=9)
        upright = next(e for e in s.equilibria if e.a_star is not None)
        lower = upright.exact_window[0]
        # The exact window opens O(ε²) from a* (ε = 0.1).
        self.assertLess(abs(lower - math.sqrt(2.0)), 0.05)

    def test_uncoupled_section_returns_to_its_seeds(self):
        m = mechlab.model("henon_heiles")
        seeds = [[0.2, 0.0], [-0.5, 0.3]]
        s = m.section(energy=0.3, seeds=seeds, crossings=20, params={"lambda": 0.0}).section
        self.assertEqual(len(s.points), 2)
        for points, seed in zip(s.points, seeds):
            self.assertEqual(points.shape, (20, 2))
            self.assertLess(np.max(np.abs(points - np.array(seed))), 1e-8)
        with self.assertRaises(mechlab.Refused):
            mechlab.model("kapitza").section(energy=0.0)

    def test_period_map_orbits_are_arrays_on_the_plane(self):
        m = mechlab.model("kapitza")
        p = m.period_map(seeds=[[0.2, 0.0]], periods=50, axes=("q", "p_q"))
        self.assertEqual(list(p.axes), ["q", "p_q"])
        self.assertEqual(p.orbits[0].shape, (51, 2))
        # Below a*, near the hanging rest, small orbits stay small.
        self.assertLess(np.max(np.abs(p.orbits[0][:, 0])), 0.3)
        with self.assertRaises(ValueError) as e:
            m.period_map(axes=("q", "nope"))
        self.assertIn("nope", str(e.exception))

    def test_chaos_map_pixels_are_where_their_rows_and_columns_say(self):
        m = mechlab.model("kapitza")
        full = m.chaos_map(pixels=6, periods=40, progress=False)
        self.assertEqual(full.fli.shape, (6, 6))
        self.assertAlmostEqual(full.fli_regular_level, math.log(40.0))
        # Pixel (i = 1, j = 3), row 0 at the bottom, as a map of its own:
        # not its transpose's value.
        (x0, x1), (y0, y1) = full.ranges
        dx, dy = (x1 - x0) / 6, (y1 - y0) / 6
        one = m.chaos_map(pixels=1, periods=40, progress=False,
                          ranges=((x0 + dx, x0 + 2 * dx), (y0 + 3 * dy, y0 + 4 * dy)))
        self.assertAlmostEqual(one.fli[0, 0], full.fli[3, 1], delta=1e-6 * abs(full.fli[3, 1]))
        self.assertGreater(abs(full.fli[3, 1] - full.fli[1, 3]), 1.0)

    def test_continuation_meets_the_floquet_window_of_stability(self):
        m = mechlab.model("kapitza")
        p = {"A": 0.5, "eps": 0.1, "mu": 0.0}
        s = m.stability(a_max=6.0, samples=120, edge_tolerance=1e-12, method="taylor", tol=1e-13, params=p)
        upright = next(e for e in s.equilibria if e.q[0] == 0.0)
        low, high = upright.exact_window
        c = m.continuation(parameter="A", to=5.0, start=[0.0, 0.0], max_period=1,
                           switch_branch_points=False, params=p)
        on_upright = [b for b in c.bifurcations if b.branch == 0]
        self.assertEqual([b.kind for b in on_upright], ["branch_point", "period_doubling"])
        self.assertAlmostEqual(on_upright[0].parameter, low, delta=1e-8)
        self.assertAlmostEqual(on_upright[1].parameter, high, delta=1e-8)

    def test_the_attractors_spectrum_sums_to_the_damping(self):
        m = mechlab.model("ueda")
        a = m.attractor(points=2000, transient=200, lyapunov_periods=1000, pixels=50)
        self.assertEqual(a.orbit.shape[1], 2)
        self.assertGreaterEqual(len(a.orbit), a.points)
        # Σλ per period = −k T for x'' + k x' + x³ = B cos t (T = 2π).
        self.assertAlmostEqual(a.lyapunov_sum, -0.05 * 2 * math.pi, delta=1e-6)
        self.assertGreater(a.lyapunov[0], 0.0)

    def test_the_averaging_error_falls_as_one_over_the_frequency(self):
        a = mechlab.model("kapitza").averaging(values=[0.05, 0.025, 0.0125], t_obs=1.0)
        for slope in a.slope:
            self.assertAlmostEqual(slope, -1.0, delta=0.1)
        with self.assertRaises(ValueError):
            mechlab.model("kapitza").averaging(order=7)

    def test_separatrix_lobe_areas_agree_by_two_routes(self):
        s = mechlab.model("kapitza").separatrix_splitting(precision="double", params={"A": 1.0, "eps": 0.3})
        self.assertTrue(s.resolved)
        self.assertLess(s.routes_relative_difference, 1e-6)
        self.assertGreater(s.lobe_area_action, 0.0)

    def test_painleve_klein_dissipates_and_switches(self):
        m = mechlab.model("painleve_klein")
        self.assertEqual(m.kind, "contact")
        r = m.explore()
        # Dry friction only takes energy: E(t) − E(0) never rises.
        self.assertTrue(np.all(np.diff(r.energy_change) <= 1e-12))
        self.assertLess(r.energy_change[-1], -1.0)
        self.assertTrue(any("stick" in s for s in r.switches))
        self.assertEqual(r.states.shape[1], 4)

    def test_energy_is_conserved_along_an_autonomous_orbit(self):
        m = mechlab.model("henon_heiles")
        y = m.integrate([0.1, 0.2, 0.3, 0.0], np.linspace(0, 50, 11), tol=1e-12)
        e = [m.energy(row) for row in y]
        # H = (p² + x² + y²)/2 + x²y − y³/3 by hand.
        x, yy, px, py = y[0]
        self.assertAlmostEqual(e[0], (px**2 + py**2 + x**2 + yy**2) / 2 + x * x * yy - yy**3 / 3, places=14)
        self.assertLess(max(abs(v - e[0]) for v in e), 1e-10)

    def test_iterates_in_the_lanes_are_the_period_maps_points(self):
        m = mechlab.model("kapitza")
        starts = np.array([[0.2, 0.0], [2.5, 0.3], [-1.0, 1.0]])
        it = m.iterates(starts, 30, tol=1e-13, params={"A": 2.0})
        self.assertEqual(it.shape, (3, 30, 2))
        p = m.period_map(seeds=starts.tolist(), periods=30, tol=1e-13, params={"A": 2.0})
        for k in range(3):
            # The portrait's points start at the seed; q is an angle. The
            # lanes take steps of their own: the two agree to the error.
            d = it[k] - p.orbits[k][1:]
            d[:, 0] = (d[:, 0] + math.pi) % (2 * math.pi) - math.pi
            self.assertLess(np.max(np.abs(d)), 1e-10)

    def test_settings_are_checked_by_their_declaration(self):
        # The same names, defaults and words as the scenes' and the studio's.
        schema = {s.analysis: s for s in mechlab.schema()}
        cell = next(d for d in schema["basins"].settings if d.name == "cell")
        self.assertEqual((cell.default, cell.range), (0.05, "> 0"))
        m = mechlab.model("duffing")
        with self.assertRaisesRegex(ValueError, "basins: no setting 'cells'"):
            m.basins(cells=0.1)
        with self.assertRaisesRegex(ValueError, r"basins: cell = 0 is outside its range \(> 0\)"):
            m.basins(cell=0.0)
        with self.assertRaisesRegex(ValueError, "chaos_map: axes = q,q"):
            mechlab.model("kapitza").chaos_map(axes=("q", "q"))

    def test_basins_labels_count_as_their_fractions(self):
        m = mechlab.model("duffing")
        b = m.basins(pixels=24, progress=False)
        self.assertEqual(b.labels.shape, (24, 24))
        self.assertGreaterEqual(len(b.attractors), 2)
        for k, a in enumerate(b.attractors):
            self.assertEqual(int(np.sum(b.labels == k)), a.starts)
            self.assertAlmostEqual(a.fraction, a.starts / 24**2)

    def test_uncoupled_oscillators_have_unit_tunes_everywhere(self):
        m = mechlab.model("henon_heiles")
        f = m.section(energy=0.1, orbits=0, frequencies=8, map_time=500, samples=1024,
                      params={"lambda": 0.0}).frequency_map
        accessible = np.isfinite(f.nu1)
        self.assertEqual(int(np.sum(accessible)), f.accessible)
        self.assertLess(np.max(np.abs(f.nu1[accessible] - 1.0)), 1e-9)
        self.assertLess(np.max(np.abs(f.nu2[accessible] - 1.0)), 1e-9)

    def test_megno_map_counts_its_chaotic_pixels(self):
        g = mechlab.model("henon_heiles").section(energy=0.125, orbits=0, map=20,
                                                  map_time=500).megno_map
        self.assertEqual(int(np.sum(np.isfinite(g.megno))), g.accessible)
        self.assertEqual(int(np.sum(g.megno > 4.0)), g.chaotic)
        self.assertGreater(g.chaotic, 0)
        with self.assertRaises(mechlab.Refused):
            mechlab.model("henon_heiles").period_map_frequencies(pixels=4, progress=False)

    def interrupt_after(self, seconds):
        """Ctrl-C in `seconds`, with Python's own handler: a process
        started in the background by a shell without job control inherits
        SIGINT ignored, and Python then keeps it ignored."""
        previous = signal.signal(signal.SIGINT, signal.default_int_handler)
        self.addCleanup(signal.signal, signal.SIGINT, previous)
        timer = threading.Timer(seconds, lambda: os.kill(os.getpid(), signal.SIGINT))
        self.addCleanup(timer.cancel)
        timer.start()

    def test_ctrl_c_stops_a_chaos_map(self):
        m = mechlab.model("kapitza")
        self.interrupt_after(0.5)
        with self.assertRaises(KeyboardInterrupt):
            m.chaos_map(pixels=400, periods=4000, progress=False)

    def test_ctrl_c_stops_any_analysis_and_the_next_call_runs(self):
        # An attractor of ten million points: no hook of its own, its
        # integrations stop at their next step.
        m = mechlab.model("ueda")
        self.interrupt_after(0.5)
        with self.assertRaises(KeyboardInterrupt):
            m.attractor(points=10_000_000, lyapunov_periods=100_000)
        s = mechlab.model("kapitza").stability(samples=6)
        self.assertAlmostEqual(s.equilibria[1].a_star, math.sqrt(2.0), places=9)


if __name__ == "__main__":
    unittest.main()


ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))


def scene_summary(scene, settings, folder):
    """The scene's summary.json with these settings (`cargo run` from the
    workspace: the example binaries the tests of the workspace built)."""
    import json
    import subprocess
    knobs = [a for name, value in settings.items() for a in ("--set", f"{name}={value}")]
    subprocess.run(["cargo", "run", "--release", "--quiet", "--example", scene, "--", *knobs,
                    "--out", folder], cwd=ROOT, check=True, capture_output=True)
    with open(os.path.join(folder, "summary.json")) as f:
        return json.load(f)


def numbers(value):
    """A summary without its timings and the scene's own record."""
    if isinstance(value, dict):
        return {k: numbers(v) for k, v in value.items()
                if "seconds" not in k and k not in ("scene", "settings")}
    if isinstance(value, (list, tuple)):
        return [numbers(v) for v in value]
    return value


class SteadyMotion(unittest.TestCase):
    """A constrained model without a fast phase: `stability` is its steady
    motion's linearisation. Chaplygin's sleigh gliding at speed u has the
    one eigenvalue -m b u / (I + m b^2) (the heading's rate)."""

    def test_the_sleigh_against_its_closed_form(self):
        sleigh = mechlab.model("chaplygin_sleigh")
        for u in (1.5, -0.5):
            result = sleigh.stability(at=u, sweep=0)
            (re, im), = result["motion"]["eigenvalues"]
            exact = -1.0 * 0.5 * u / (0.5 + 1.0 * 0.5 ** 2)
            self.assertLessEqual(abs(re - exact), result["motion"]["errors"][0])
            self.assertEqual(im, 0.0)
            self.assertEqual("unstable" in result["motion"]["verdict"], u < 0)
            self.assertEqual(result["matrix"].shape, (1, 1))

    def test_a_top_without_constraints_finds_its_tilt(self):
        # The heavy top hanging and precessing at 2 without spin: the tilt
        # found by Newton's method solves (A - C) W^2 cos(theta) + m g l = 0,
        # cos(theta) = -1/4 at the defaults (A = 2, C = m = g = l = 1).
        top = mechlab.model("heavy_top")
        result = top.steady_motion(speed="phi", at=2.0, rates=(2.0, 0.0, 0.0),
                                   start=(0.0, 1.5, 0.0), sweep=0)
        self.assertEqual(result["shape"], ["theta"])
        self.assertAlmostEqual(math.cos(result["motion"]["state"][1]), -0.25, places=9)
        for (re, im), error in zip(result["motion"]["eigenvalues"], result["motion"]["errors"]):
            self.assertLessEqual(abs(re), error)
            self.assertGreater(abs(im), 1.0)


class SameNumbersAsTheScenes(unittest.TestCase):
    """Same settings, same numbers: Python and the scene of each analysis,
    field by field of the scene's summary."""

    CASES = [
        ("period_map", "kapitza", {"periods": 60, "count": 4}, {}),
        ("attractor", "ueda", {"points": 3000, "transient": 100, "lyapunov_periods": 400,
                               "pixels": 40}, {}),
        ("averaging", "double_pendulum", {"values": "geometric:100,400,3", "t_obs": 1.0}, {}),
        ("linkage", "four_bar", {"scan": 6, "orbits": 2, "periods": 20}, {}),
        ("steady_motion", "chaplygin_sleigh", {"at": 0.5, "sweep": 11}, {"b": 0.3}),
        ("stability", "kapitza", {"samples": 30}, {"eps": 0.2}),
        ("chaos_map", "kapitza", {"pixels": 6, "periods": 30}, {"A": 1.2}),
        ("basins", "duffing", {"pixels": 8, "transient": 40}, {}),
    ]

    def test_each_analysis(self):
        import tempfile
        for analysis, model, settings, params in self.CASES:
            with self.subTest(analysis=analysis), tempfile.TemporaryDirectory() as folder:
                knobs = {"model": model, **settings, **params}
                if analysis in ("chaos_map", "basins"):
                    knobs["tile_rows"] = 0
                scene = numbers(scene_summary(analysis, knobs, folder))
                method = getattr(mechlab.model(model), analysis)
                extra = {"progress": False} if analysis in ("chaos_map", "basins") else {}
                result = method(params=params, **settings, **extra)
                for key, value in scene.items():
                    got = result[key]
                    got = got.tolist() if hasattr(got, "tolist") else got
                    self.assertEqual(numbers(got), value, f"{analysis}: {key}")
