"""Views of results: matplotlib figures, Meshcat scenes, static HTML."""
