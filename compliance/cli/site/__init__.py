"""Commands about a site's own recordings (``govcheck accept``)."""
