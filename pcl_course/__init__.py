"""3D Point Cloud Processing, Lecture 1: the student package.

Exercise modules (implement the stubs): :mod:`pca`, :mod:`normals`,
:mod:`downsampling`, :mod:`filters`, :mod:`metrics`.

Complete helpers (use them): :mod:`validation`, :mod:`datasets`, :mod:`io`,
:mod:`neighbors`, :mod:`plotting`, :mod:`book`.
"""

import os as _os

# Open3D starts a WebRTC visualiser (and prints about it) when imported in
# Jupyter; the book draws with matplotlib and Plotly and needs neither.
_os.environ.setdefault("OPEN3D_DISABLE_WEB_VISUALIZER", "true")
