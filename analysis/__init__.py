"""Analysis: pure math of arrays (cost_of_transport, reward, return_map, series, landscape) and the figures and reports drawn from saved records (figures, stability_report, reproduce_report)."""
