"""Permeability of the bundled soybean scene by the pore network, beside Kozeny-Carman.

Run from the repository root: ``python docs/examples/quickstart.py``.
"""
import network

packing = network.read_packing(network.default_packing_path())  # 3000 spheres, metres
result = network.solve_network(packing)  # Stokes flow along z through the interior sample

k_kc = network.kozeny_carman_permeability(result.porosity, result.sauter_diameter_m)
print(f"spheres          {packing.n}")
print(f"porosity         {result.porosity:.4f}")
print(f"permeability     {result.permeability_m2:.4e} m2 (Kozeny-Carman {k_kc:.4e} m2)")
print(f"pressure drop    {result.pressure_drop_pa:.3f} Pa over {result.depth_m} m "
      f"at {result.velocity_m_s} m/s")
print(f"mass balance     {result.check['balance_error']:.1e}")
