"""Reach: where an arm's tool can go, and where to put the arm (SI units: m, rad).

- :mod:`.workspace` (sampled workspace), :mod:`.joint_samples` (slices of the seeded joint
  samples), :mod:`.dexterity` (position manipulability and inverse condition),
  :mod:`.sphere_fit` (sphere fits), :mod:`.workspace_stream` (streamed, for large samples;
  its mergeable reductions: :mod:`.stream_reduction`), :mod:`.voxels` (voxel maps of a
  workspace);
- :mod:`.orientations` (tool orientation sets), :mod:`.reachability` (reachability maps:
  how many orientations each voxel reaches), built from :mod:`.reach_grid` (the reach bound
  and the voxels computed), :mod:`.reach_chunk` (solving one chunk of voxels) and
  :mod:`.robot_spec` (the robot a worker rebuilds); :mod:`.reach_map` (the map as data),
  :mod:`.reach_io` (its HDF5 file format, read in a bounded child process:
  :mod:`._reach_child`, :mod:`._reach_worker`) and :mod:`.reach_write` (writing it);
- :mod:`.inverse_reach` (inverse reach: bases from which an arm reaches a set of poses,
  checked by exact IK in :mod:`.base_verify`), :mod:`.table_band` (the recommended table
  band), :mod:`.layout` (checking a station's layout).

The public names are re-exported by :mod:`pinarms.robots` (old module paths: docs/README.md).
"""

__all__: list[str] = []
