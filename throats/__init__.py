"""grainflow.throats (under construction: see the open issue)."""
