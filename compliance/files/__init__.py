"""Output files: the one atomic writer, the one JSON cleaner, and paths as a reader should see them."""
