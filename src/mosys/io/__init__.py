"""The HDF5 contracts (docs/formats/), atomic writes and progress lines."""
