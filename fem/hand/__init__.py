"""softhand.fem.hand."""
