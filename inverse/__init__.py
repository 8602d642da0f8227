"""inverse package."""
