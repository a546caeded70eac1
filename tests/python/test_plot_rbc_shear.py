"""The orientation measure of scripts/plot_rbc_shear.py on synthetic discs: a rigid oblate ellipsoid turning about
y (tumbling) and a fixed ellipsoid whose surface points travel around it (tank-treading). Run by CTest with
/usr/bin/python3 (numpy, matplotlib)."""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import plot_rbc_shear as prs  # noqa: E402


def unit_sphere(n_theta=24, n_phi=48):
    """Nodes and triangles of a latitude-longitude sphere of radius 1 (poles at +-z)."""
    nodes = [[0.0, 0.0, 1.0]]
    for i in range(1, n_theta):
        t = np.pi * i / n_theta
        for j in range(n_phi):
            p = 2 * np.pi * j / n_phi
            nodes.append([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)])
    nodes.append([0.0, 0.0, -1.0])
    ring = lambda i, j: 1 + (i - 1) * n_phi + j % n_phi  # noqa: E731
    tris = [[0, ring(1, j), ring(1, j + 1)] for j in range(n_phi)]
    for i in range(1, n_theta - 1):
        for j in range(n_phi):
            tris += [[ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)], [ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]]
    south = len(nodes) - 1
    tris += [[south, ring(n_theta - 1, j + 1), ring(n_theta - 1, j)] for j in range(n_phi)]
    return np.array(nodes), np.array(tris)


def about_y(angle):
    """Rotation about y turning +z towards +x by `angle` (the sense of the shear u = (k z, 0, 0))."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


# An ellipsoid with semi-axes 4 (x), 3.5 (y), 1.2 (z): the z axis is its axis of the largest moment of inertia.
SEMI_AXES = np.array([4.0, 3.5, 1.2])
CENTRE = np.array([10.0, 5.0, -3.0])


def disc(orientation, material_turn):
    """The ellipsoid with its short axis at `orientation` from z towards x; its surface points moved around it by
    `material_turn` (a turn about y in the parameter sphere, which maps the surface onto itself)."""
    p, tris = unit_sphere()
    body = (p @ about_y(material_turn).T) * SEMI_AXES
    return body @ about_y(orientation).T + CENTRE, tris


class Orientation(unittest.TestCase):
    def test_symmetry_axis_is_the_short_axis(self):
        for angle in (0.0, 0.4, -1.1, 2.0):
            nodes, tris = disc(angle, 0.0)
            c, n = prs.symmetry_axis(nodes, tris)
            np.testing.assert_allclose(c, CENTRE, atol=1e-9)
            self.assertAlmostEqual(abs(np.dot(n, [np.sin(angle), 0.0, np.cos(angle)])), 1.0, places=9)

    def test_a_tumbling_disc_advances_phi_by_pi_per_flip(self):
        kt = np.linspace(0.0, 20.0, 161)
        truth = 0.5 * kt + 0.3 * np.sin(kt)  # turning at a varying rate, always forward, 10 rad in all
        phi, psi = prs.orientation([disc(a, 0.0) for a in truth])
        np.testing.assert_allclose(phi, truth, atol=1e-9)
        rel = psi - phi
        np.testing.assert_allclose(rel, rel[0], atol=1e-9)  # the node rides with the body
        s = prs.summary(kt, phi, psi)
        self.assertEqual(s["flips"], int(10.0 // np.pi))
        self.assertAlmostEqual(s["f_tt"], 0.0, places=9)

    def test_a_tank_treading_disc_swings_and_its_membrane_turns(self):
        kt = np.linspace(0.0, 8 * np.pi, 401)
        truth = -0.3 + 0.1 * np.sin(kt)
        turn = 0.5 * kt  # one material turn per 4 pi of k t: f_tt / k = 1 / (4 pi)
        phi, psi = prs.orientation([disc(a, b) for a, b in zip(truth, turn)])
        # The moved nodes make another polyhedron each frame: its axes deviate from the ellipsoid's by under 1e-3.
        np.testing.assert_allclose(phi, truth, atol=1e-3)
        s = prs.summary(kt, phi, psi)
        self.assertEqual(s["flips"], 0)
        self.assertAlmostEqual(s["phi_mean"], np.mean(truth[kt >= 4 * np.pi]), delta=1e-3)
        self.assertAlmostEqual(s["phi_min"], -0.4, delta=2e-3)
        self.assertAlmostEqual(s["phi_max"], -0.2, delta=2e-3)
        self.assertAlmostEqual(s["f_tt"], 1 / (4 * np.pi), places=9)


if __name__ == "__main__":
    unittest.main()
