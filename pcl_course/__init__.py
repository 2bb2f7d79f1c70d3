"""3D Point Cloud Processing: the student package.

Exercise modules (implement the stubs), by lecture:

- lecture 1, PCA, normals, downsampling and filters: :mod:`pca`,
  :mod:`normals`, :mod:`downsampling`, :mod:`filters`, :mod:`metrics`;
- lecture 2, nearest neighbours: :mod:`nn`;
- lecture 3, clustering: :mod:`cluster`.

Complete helpers (use them): :mod:`validation`, :mod:`datasets`, :mod:`io`,
:mod:`neighbors`, :mod:`plotting`, :mod:`book`; :func:`check` grades an
exercise from a notebook cell (:mod:`checking`).
"""

import os as _os

# Open3D starts a WebRTC visualiser (and prints about it) when imported in
# Jupyter; the book draws with matplotlib and Plotly and needs neither.
_os.environ.setdefault("OPEN3D_DISABLE_WEB_VISUALIZER", "true")

from pcl_course.checking import check as check  # noqa: E402  (check("pca") in a notebook cell)
