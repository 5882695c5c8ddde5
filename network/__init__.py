"""grainflow.network (under construction: see the open issue)."""
