"""The Python module against independent references: brute-force sphere
overlaps, the budget, momentum of a head-on bounce, errors with messages."""
import os
import pathlib
import tempfile
import unittest

import numpy as np

import icd

DATA = pathlib.Path(os.environ.get("ICD_DATA_DIR", "data"))


def brute_force_leaf_pairs(a, b):
    """Every pair of overlapping leaf spheres (leaves: no children)."""
    sa, sb = a.spheres, b.spheres
    la = np.flatnonzero(a.child_count == 0)
    lb = np.flatnonzero(b.child_count == 0)
    d = np.linalg.norm(sa[la, None, :3] - sb[None, lb, :3], axis=2)
    i, j = np.nonzero(d <= sa[la, None, 3] + sb[None, lb, 3])
    return {(int(la[p]), int(lb[q])) for p, q in zip(i, j)}


class ModuleTest(unittest.TestCase):
    def test_imported_from_the_expected_tree(self):
        self.assertTrue(icd.__version__)
        if os.environ.get("ICD_EXPECT_INSTALLED"):
            self.assertIn("install-tree", icd.__file__)

    def test_mesh_round_trip(self):
        s = icd.make_icosphere(2, 0.5)
        self.assertEqual(s.F.shape[1], 3)
        np.testing.assert_allclose(np.linalg.norm(s.V, axis=1), 0.5, rtol=1e-12)
        with tempfile.TemporaryDirectory() as d:
            p = pathlib.Path(d) / "s.obj"
            icd.write_surface_mesh(p, s)
            r = icd.read_surface_mesh(p)
            np.testing.assert_allclose(r.V, s.V, rtol=1e-12, atol=1e-15)
            np.testing.assert_array_equal(r.F, s.F)

    def test_errors_name_the_file(self):
        with self.assertRaises(icd.InputError) as e:
            icd.read_surface_mesh("/nonexistent/x.off")
        self.assertIn("/nonexistent/x.off", str(e.exception))
        with self.assertRaises(ValueError):
            icd.collide(icd.SphereTree(), icd.SphereTree())

    def test_full_query_equals_brute_force_and_budget_holds(self):
        s = icd.make_icosphere(3, 1.0)
        a = icd.build_octree_tree(s.V, s.F, levels=4)
        b = icd.build_octree_tree(s.V + np.array([1.5, 0.2, 0.0]), s.F, levels=4)
        full = icd.collide(a, b, icd.CollisionRequest())
        self.assertFalse(full.interrupted)
        got = {tuple(p) for p in full.colliding.tolist()}
        # A full query reports only overlapping leaf pairs (each one is in
        # the brute-force set), and these touching spheres have some.
        self.assertTrue(got)
        self.assertTrue(got <= brute_force_leaf_pairs(a, b))
        cut = icd.collide(a, b, icd.CollisionRequest(budget_tests=50))
        self.assertTrue(cut.interrupted)
        self.assertLessEqual(cut.tests, 50)
        self.assertEqual(cut.stop_reason, icd.StopReason.TestBudget)
        self.assertGreater(len(cut.untested), 0)

    def test_sph_round_trip(self):
        s = icd.make_icosphere(2, 1.0)
        t = icd.build_octree_tree(s.V, s.F, levels=3)
        with tempfile.TemporaryDirectory() as d:
            p = str(pathlib.Path(d) / "t.sph")
            icd.write_sph(p, t)
            r = icd.read_sph(p)
            self.assertEqual(r.num_levels, t.num_levels)
            np.testing.assert_allclose(r.spheres, t.spheres, rtol=1e-9)

    def test_two_balls_bounce_with_momentum_kept_and_a_probe_callback(self):
        ball = icd.make_primitive("sphere", radius=0.1, subdivisions=2, cells=5)
        objs = [icd.WorldObject("left", ball.placed(position=[-0.12, 0, 0]), velocity=[0.6, 0, 0], young=5e5),
                icd.WorldObject("right", ball.placed(position=[0.12, 0, 0]), velocity=[-0.6, 0, 0], young=5e5)]
        settings = icd.WorldSettings()
        settings.collision.query.budget_tests = 1000000
        settings.collision.query.budget_seconds = float("inf")
        settings.collision.stiffness = 2000
        w = icd.World(objs, settings)
        self.assertEqual(w.names, ["left", "right"])
        calls = []
        w.on_step(lambda world: calls.append(world.num_objects))
        contact = 0
        for _ in range(40):
            contact += w.step().active_pairs > 0
        self.assertEqual(len(calls), 40)
        self.assertGreater(contact, 0)
        m = w.node_masses(0)
        p0, p1 = m @ w.velocities(0), w.node_masses(1) @ w.velocities(1)
        self.assertLess(p0[0] / m.sum(), -0.1)  # bounced apart
        self.assertGreater(p1[0] / m.sum(), 0.1)
        # Contact forces are equal and opposite: total momentum stays zero.
        self.assertLess(np.linalg.norm(p0 + p1), 1e-9 * m.sum())

    def test_scene_overrides_as_icd_run_set(self):
        scene = pathlib.Path(__file__).resolve().parents[2] / "experiments/scenes/two_spheres.json"
        with tempfile.TemporaryDirectory() as cache:
            moving = icd.World.from_scene(str(scene), cache_dir=cache)
            still = icd.World.from_scene(
                str(scene), overrides=["objects.0.velocity=[0,0,0]", "objects.1.velocity=[0, 0, 0]"],
                cache_dir=cache)
            # The scene's own velocities (0.6 m/s towards each other) against none.
            self.assertAlmostEqual(float(moving.velocities(0)[:, 0].mean()), 0.6, places=9)
            self.assertLess(float(np.abs(still.velocities(0)[:, 0]).max()), 1e-12)
            with self.assertRaisesRegex(Exception, "velocty"):
                icd.World.from_scene(str(scene), overrides=["objects.0.velocty=[0,0,0]"], cache_dir=cache)

    def test_external_force_accelerates_as_newton_says(self):
        ball = icd.make_primitive("sphere", radius=0.1, subdivisions=1, cells=3)
        w = icd.World([icd.WorldObject("b", ball, young=1e6)])
        n = w.positions(0).shape[0]
        f = np.zeros((n, 3))
        f[:, 2] = 1.0  # 1 N per node
        w.set_external_forces(0, f)
        w.step()
        # Newton on a free body: internal forces sum to zero, so after one
        # frame (1/60 s) the momentum is the total load times the time.
        p = w.node_masses(0) @ w.velocities(0)
        np.testing.assert_allclose(p, [0, 0, n / 60.0], atol=1e-9 * n)
        with self.assertRaises(icd.ParameterError) as e:
            w.set_external_forces(0, np.zeros((n + 1, 3)))
        self.assertIn('"b"', str(e.exception))

    @unittest.skipUnless((DATA / "bunny00.off").exists(), "bunny not fetched")
    def test_bunny_bundle_collides_and_steps(self):
        if not hasattr(icd, "preprocess"):
            self.skipTest("built without the CGAL preprocessing module")
        with tempfile.TemporaryDirectory() as d:
            b = icd.preprocess(DATA / "bunny00.off", pathlib.Path(d) / "bunny", coarse_tets=400,
                               spheres=False)
            b = icd.read_asset_bundle(pathlib.Path(d) / "bunny").with_octree_spheres(3)
        left, right = b.placed(0.3, [-0.12, 0, 0]), b.placed(0.3, [0.12, 0, 0])
        r = icd.collide(left.spheres, right.spheres, icd.CollisionRequest(budget_tests=5000))
        self.assertLessEqual(r.tests, 5000)
        self.assertGreater(len(r.colliding) + len(r.untested), 0)
        s = icd.WorldSettings()
        s.collision.query.budget_tests = 5000
        w = icd.World([icd.WorldObject("l", left, velocity=[0.2, 0, 0], young=3e5),
                       icd.WorldObject("r", right, velocity=[-0.2, 0, 0], young=3e5)], s)
        self.assertGreater(sum(w.step().active_pairs > 0 for _ in range(5)), 0)


if __name__ == "__main__":
    unittest.main()
