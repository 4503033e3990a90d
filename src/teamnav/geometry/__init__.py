"""SE(2) and similarity transforms, angles, frames from mutual bearings."""
