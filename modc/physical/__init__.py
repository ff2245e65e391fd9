"""Physical model: representative part geometry, meshes and inertials of an assembled arm."""
