"""The plant model: configuration files, the one parameter schema, the parameter vector, the
assembly of physics and declared effects into one compiled right-hand side, controller pieces."""
