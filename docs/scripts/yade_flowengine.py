"""YADE's FlowEngine on a packing CSV (x,y,z,r in m): timed beside ours on the same host.

Run by YADE, not by Python (Debian: ``apt-get install yade``)::

    yade -n -x docs/scripts/yade_flowengine.py bench_5000_s1.csv [SOLVER]

The spheres are fixed, six walls sit at their bounding box (``aabbWalls``), pressure 1 on the
lower z wall and 0 on the upper one, the x/y walls no-flow, viscosity 1; ``SOLVER`` is
FlowEngine's ``useSolver`` (default 3, CHOLMOD). Printed: the first ``emulateAction()``
(triangulation, throat geometry, factorisation, solve: what "FlowEngine's time" means in
``docs/network-bench.md``), the second (re-triangulation and solve), the flux through the lower
wall and the permeability q L / (A dp). The walls and FlowEngine's defaults are not tuned to
this packing: compare the times, not the permeability (``docs/network-bench.md``, "Per packing").
Not part of the package.
"""
import sys, time, numpy as np
path = sys.argv[1]
d = np.loadtxt(path, delimiter=',', skiprows=1)
c, r = d[:, :3], d[:, 3]
lo = (c - r[:, None]).min(0); hi = (c + r[:, None]).max(0)
walls = aabbWalls([Vector3(*lo), Vector3(*hi)], thickness=0)
wid = O.bodies.append(walls)
O.bodies.append([sphere(Vector3(*ci), float(ri), fixed=True) for ci, ri in zip(c, r)])
O.engines = [ForceResetter(),
             InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
                             [Ip2_FrictMat_FrictMat_FrictPhys()], [Law2_ScGeom_FrictPhys_CundallStrack()]),
             FlowEngine(dead=1, label="flow"),
             NewtonIntegrator()]
flow.wallIds = wid
flow.bndCondIsPressure = [0, 0, 0, 0, 1, 1]
flow.bndCondValue = [0, 0, 0, 0, 1, 0]
flow.boundaryUseMaxMin = [0, 0, 0, 0, 0, 0]
flow.viscosity = 1.0
flow.useSolver = int(sys.argv[2]) if len(sys.argv) > 2 else 3
t0 = time.perf_counter()
flow.emulateAction()
t1 = time.perf_counter()
q = flow.getBoundaryFlux(wid[4])
L = hi[2] - lo[2]; A = (hi[0] - lo[0]) * (hi[1] - lo[1])
k = q * 1.0 * L / (A * 1.0)
t2 = time.perf_counter()
flow.updateTriangulation = True
flow.emulateAction()
t3 = time.perf_counter()
print(f"YADE FlowEngine {len(r)} spheres, solver {flow.useSolver}: first emulateAction {t1 - t0:.3f} s, second {t3 - t2:.3f} s, flux {q:.4e}, k {k:.4e} m2")
