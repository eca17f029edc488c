"""A fill-reducing order for the direct factorization of a 3D implicit step
(``time.direct_ordering``).

CHOLMOD as cvxopt bundles it orders by AMD, a local (minimum-degree) heuristic; on the implicit
step's 3D matrices, whose rows couple every node within two cells (375 entries a row), nested
dissection leaves less fill: the graph is cut by small separators recursively, each
separator eliminated last (George 1973; METIS's multilevel version, Karypis and Kumar 1998).
The order is computed on the graph of the nodes, not of their velocity components (in 3D 3x
fewer vertices and 9x fewer edges; the components of one node are ordered together), by METIS
through pymetis.
"""

import numpy as np
import scipy.sparse as sp

# below this many nodes AMD's order is kept (a choice: on such small systems the fill, and
# what an order can save, is small)
NESTED_MIN_NODES = 200


def nested_dissection(A: sp.csr_matrix, node: np.ndarray) -> np.ndarray | None:
    """The elimination order of A's unknowns (order[k]: the unknown eliminated k-th) from
    METIS's nested dissection of the graph of their nodes (``node[i]``: a label of unknown i's
    node); None for a system under NESTED_MIN_NODES nodes (AMD's order then)."""
    labels, first, of_unknown = np.unique(node, return_index=True, return_inverse=True)
    nodes = len(labels)
    if nodes < NESTED_MIN_NODES:
        return None
    import pymetis

    # the nodes' graph: the rows and columns of each node's first unknown (a node's tangent
    # block is dense, so two nodes couple wherever any of their components do)
    graph = A[first][:, first].tocsr()
    graph.setdiag(0)
    graph.eliminate_zeros()
    graph.sort_indices()
    order, _ = pymetis.nested_dissection(
        pymetis.CSRAdjacency(graph.indptr.astype(np.int64), graph.indices.astype(np.int64))
    )
    rank = np.empty(nodes, dtype=np.int64)
    rank[np.asarray(order, dtype=np.int64)] = np.arange(nodes)
    # the unknowns by their node's rank, a node's components in their own order
    return np.lexsort((np.arange(len(node)), rank[of_unknown]))
