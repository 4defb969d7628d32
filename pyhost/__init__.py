"""The Python host: scene loading, engine bridges, the coupling loop and the CLI."""
