"""vehicles package."""
