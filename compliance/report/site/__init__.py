"""The site acceptance report (``govcheck accept --report``): built from a site results dict alone."""
