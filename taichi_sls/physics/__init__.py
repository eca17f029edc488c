"""The model's equations as Taichi functions: shape functions, materials, the Perzyna return map,
MPM transfers, heat and laser, level set, curvature and the capillary forces. Functions take the
fields they read and write as arguments; this layer knows no case file, output or study."""
