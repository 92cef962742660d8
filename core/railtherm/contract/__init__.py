"""What a plugin implements and what every result looks like: stage interfaces and their result
objects, hooks, errors, the surface grid, the result schema and model options."""
