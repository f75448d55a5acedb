"""The types every stage shares: classes, the pixel grid, plans, parsed plans, errors."""
