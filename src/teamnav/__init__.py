"""teamnav: simulator, library and CLI for robot teams that help each other navigate."""

__version__ = "0.1.0"
