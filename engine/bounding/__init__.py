"""Bounding volumes (chapter: "Volumes englobants"): sphere, AABB, OBB, k-DOP, convex hull, decomposition."""
