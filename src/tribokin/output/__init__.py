"""The output folder: written atomically, one run at a time, with CSV/JSON tables and figures."""
