"""roadlib package."""
