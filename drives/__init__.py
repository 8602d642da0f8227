"""drives package."""
