"""Other step controllers to compare with the RSG: placo's walk pattern generator."""
