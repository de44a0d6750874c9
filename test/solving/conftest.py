"""Puts this folder on the import path, so that the tests beneath it share the problems of
`solver_instances` and the table of `known_optima`."""
