"""Wrong: the student's own loop (libigl's boundary_loop, reversed to run the other way):
the disk comes out mirrored."""

import igl
import operator_helpers as oh


def tutte_map(V, F, loop, weights):
    mine = igl.boundary_loop(F)[::-1]
    K = oh.graph_stiffness(F, len(V)) if weights == "uniform" else oh.cot_stiffness(V, F)
    return oh.solve_known(K, mine, oh.circle_by_arc_length(V, mine))
