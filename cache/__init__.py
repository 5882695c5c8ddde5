"""grainflow.cache (under construction: see the open issue)."""
