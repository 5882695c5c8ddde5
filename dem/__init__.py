"""grainflow.dem (under construction: see the open issue)."""
