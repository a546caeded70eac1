"""A run folder read by common Python tools without hand work: membranes.xdmf by meshio's XDMF time series reader
(all membranes in one surface per frame, cell data membrane_id, the moving nodes as the field "position"),
diagnostics.csv and its table of units by numpy; the same files written by two MPI processes together. Run by CTest
with /usr/bin/python3 (python3-meshio)."""
import os
import subprocess
import tempfile
import unittest
from pathlib import Path

import h5py
import meshio
import numpy as np

PROGRAM = os.environ["IMMERSE_PROGRAM"]
MPIEXEC = os.environ["IMMERSE_MPIEXEC"]
# What OpenMPI needs to start as root and without a remote launcher.
MPI_ENV = dict(os.environ, OMP_NUM_THREADS="1", OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_plm="isolated", OMPI_MCA_btl_vader_single_copy_mechanism="none")

# Two spheres of radius 1 side by side in a periodic box (nondimensional units), one stretched along x.
CONFIG = """
[scenario]
kind = "custom"
[domain]
Lx = 8.0
Ly = 4.0
Lz = 4.0
[grid]
nx = 32
ny = 16
nz = 16
[fluid]
rho = 1.0
mu = 1.0
[time]
dt = 0.02
end = 0.06
[output]
fields_every = 1
[[membrane]]
shape = "ellipsoid"
semi_axes = [1.2, 1.0, 1.0]
reference = "sphere"
reference_radius = 1.0
center = [2.0, 2.0, 2.0]
Es = 1.0
mesh.level = 1
[[membrane]]
radius = 1.0
center = [6.0, 2.0, 2.0]
Es = 1.0
mesh.level = 1
"""


class OutputFiles(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.dir = Path(cls.tmp.name)
        (cls.dir / "two.toml").write_text(CONFIG)
        cls.out = cls.dir / "out"
        subprocess.run([PROGRAM, "run", str(cls.dir / "two.toml"), "--out", str(cls.out)], check=True,
                       stdout=subprocess.DEVNULL, env=dict(os.environ, OMP_NUM_THREADS="1"))

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_meshio_reads_the_membrane_series_with_ids_and_moving_nodes(self):
        with meshio.xdmf.TimeSeriesReader(str(self.out / "membranes.xdmf")) as reader:
            points, cells = reader.read_points_cells()
            self.assertEqual(points.shape, (2 * 162, 3))
            self.assertEqual([c.type for c in cells], ["triangle6"])
            self.assertEqual(reader.num_steps, 4)  # steps 0 to 3
            times, first = [], None
            for k in range(reader.num_steps):
                t, point_data, cell_data = reader.read_data(k)
                times.append(t)
                ids = cell_data["membrane_id"][0]
                self.assertEqual(sorted(set(ids.tolist())), [0, 1])
                self.assertEqual(int((ids == 0).sum()), 80)
                with h5py.File(self.out / f"fields_{k:06d}.h5", "r") as f:
                    np.testing.assert_array_equal(point_data["position"], f["membranes/nodes"][()])
                    self.assertEqual(f["membranes"].attrs["names"], "membrane0 membrane1")
                first = point_data["position"] if first is None else first
            np.testing.assert_allclose(times, [0.0, 0.02, 0.04, 0.06])
            # The stretched membrane moves (relaxes towards its sphere); the first frame is the mesh read above.
            np.testing.assert_array_equal(first, points)
            self.assertGreater(np.abs(point_data["position"][:162] - points[:162]).max(), 1e-6)

    def test_numpy_reads_the_diagnostics_and_their_units(self):
        rows = np.genfromtxt(self.out / "diagnostics.csv", delimiter=",", names=True)
        units = np.genfromtxt(self.out / "diagnostics.columns.csv", delimiter=",", names=True, dtype=None,
                              encoding=None)
        self.assertEqual(list(units["column"]), list(rows.dtype.names))
        unit = dict(zip(units["column"], units["unit"]))
        self.assertEqual((unit["time"], unit["m0_volume"], unit["m1_theta"]), ("s", "m^3", "rad"))
        np.testing.assert_allclose(rows["time"], [0.0, 0.02, 0.04, 0.06])
        # The energy budget: the stretched capsule relaxes, the energy goes into the fluid and is dissipated.
        self.assertEqual((unit["E_kinetic"], unit["dissipation"], unit["m1_E_elastic"], unit["budget_residual"]),
                         ("J", "W", "J", "J"))
        self.assertGreater(rows["m0_E_elastic"][0], 0)
        self.assertTrue(np.all(np.diff(rows["E_total"]) < 0))
        np.testing.assert_allclose(rows["E_total"], rows["E_kinetic"] + rows["m0_E_elastic"] + rows["m1_E_elastic"],
                                   rtol=1e-14)


class OutputFilesOverMpi(OutputFiles):
    """The same run with midpoint RK2 (a distributed run takes the explicit schemes) on two MPI processes, whose
    frames are written together with parallel HDF5: read by the same tools, and equal to the frames of one process."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.dir = Path(cls.tmp.name)
        (cls.dir / "two.toml").write_text(CONFIG)
        cls.out = cls.dir / "out"
        cls.serial = cls.dir / "serial"
        for processes, out in ((2, cls.out), (1, cls.serial)):
            subprocess.run([MPIEXEC, "-q", "-n", str(processes), "--oversubscribe", PROGRAM, "run",
                            str(cls.dir / "two.toml"), "--out", str(out), "--set", "time.scheme=rk2"], check=True,
                           stdout=subprocess.DEVNULL, env=MPI_ENV)

    def test_frames_equal_those_of_one_process(self):
        def datasets(f):
            found = {}
            f.visititems(lambda name, item: found.update({name: item[()]}) if isinstance(item, h5py.Dataset) else None)
            return found

        for k in range(4):
            with h5py.File(self.out / f"fields_{k:06d}.h5", "r") as a, \
                    h5py.File(self.serial / f"fields_{k:06d}.h5", "r") as b:
                mine, theirs = datasets(a), datasets(b)
                self.assertEqual(sorted(mine), sorted(theirs))
                for name in theirs:
                    self.assertEqual((mine[name].shape, mine[name].dtype), (theirs[name].shape, theirs[name].dtype))
                    scale = max(np.abs(theirs[name]).max(), 1e-300)
                    self.assertLess(np.abs(mine[name] - theirs[name]).max() / scale, 1e-10, name)
                self.assertEqual(a.attrs["xdmf_membranes"], b.attrs["xdmf_membranes"])
                self.assertEqual(a.attrs["xdmf_fluid"], b.attrs["xdmf_fluid"])
        # The energy columns: each process sums its slab's planes, added in plane order as one process does.
        mine = np.genfromtxt(self.out / "diagnostics.csv", delimiter=",", names=True)
        theirs = np.genfromtxt(self.serial / "diagnostics.csv", delimiter=",", names=True)
        for name in ("E_kinetic", "dissipation", "m0_E_elastic", "m1_E_elastic", "E_total"):
            np.testing.assert_allclose(mine[name], theirs[name], rtol=1e-10, err_msg=name)
        with h5py.File(self.out / "fields_000000.h5", "r") as a:
            # Each process's thread policy (OMP_NUM_THREADS=1 here), as rank 0 states it.
            self.assertEqual(a.attrs["threads"], "1 (fixed by OMP_NUM_THREADS) on each of 2 MPI processes")


if __name__ == "__main__":
    unittest.main()
