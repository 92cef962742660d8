"""The output folder's one owner: layout, atomic writes, readers, run and crash records."""
