"""diagnosis package."""
