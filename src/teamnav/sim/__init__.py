"""The simulator: owns the truth (true poses, the map), applies sensor, odometry and radio models."""
