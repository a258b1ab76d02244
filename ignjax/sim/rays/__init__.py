"""Ray casting: :mod:`~ignjax.sim.rays.exact` (``mjx.ray`` with the cylinder
fix, and the ``mj_ray`` references), :mod:`~ignjax.sim.rays.fast` (the voxel
march over a :class:`~ignjax.scenes.raygrid.RayGrid`) and
:mod:`~ignjax.sim.rays.queries` (the simulator's per-episode ray queries)."""
