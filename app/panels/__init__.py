"""One module per panel of the viewer, each a class following :class:`.base.Panel`."""
