"""The edge where results are written out: text tables, JSON-ready dictionaries and CSV
(report), pictures (plots), meshcat scenes and views (view, viewserver)."""
