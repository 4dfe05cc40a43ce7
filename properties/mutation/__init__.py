"""Mutation testing of the engine with mutmut 3 (tox -e mutation); see properties/MUTATION.md."""
