"""Closest point of a triangle to a point, with the Voronoi region it lies in.

Ericson, *Real-Time Collision Detection* (2005), sec. 5.1.5 ``ClosestPtPointTriangle``: the point p is
classified against the triangle's vertex, edge and face Voronoi regions with dot products only, and
the closest point is returned as barycentric weights (u, v, w) of the corners (a, b, c). The region
says which feature of the triangle the contact is with, which the contact interface needs to count
a contact once where triangles share an edge or a vertex.
"""

import taichi as ti

from wheelsoil.taichi_types import nd_i32, nd_vec3, vec3

#: Feature codes: the face interior, the edges ab, bc, ca and the vertices a, b, c.
FACE, EDGE_AB, EDGE_BC, EDGE_CA, VERTEX_A, VERTEX_B, VERTEX_C = range(7)


@ti.func
def closest_point_on_triangle(p: vec3, a: vec3, b: vec3, c: vec3):
    """Barycentric weights (of a, b, c) of the point of triangle abc closest to p, and its feature code."""
    ab = b - a
    ac = c - a
    ap = p - a
    d1 = ab.dot(ap)
    d2 = ac.dot(ap)
    bary = vec3(1.0, 0.0, 0.0)
    feature = VERTEX_A
    if not (d1 <= 0.0 and d2 <= 0.0):
        bp = p - b
        d3 = ab.dot(bp)
        d4 = ac.dot(bp)
        if d3 >= 0.0 and d4 <= d3:
            bary = vec3(0.0, 1.0, 0.0)
            feature = VERTEX_B
        else:
            vc = d1 * d4 - d3 * d2
            if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
                t = d1 / (d1 - d3)
                bary = vec3(1.0 - t, t, 0.0)
                feature = EDGE_AB
            else:
                cp = p - c
                d5 = ab.dot(cp)
                d6 = ac.dot(cp)
                if d6 >= 0.0 and d5 <= d6:
                    bary = vec3(0.0, 0.0, 1.0)
                    feature = VERTEX_C
                else:
                    vb = d5 * d2 - d1 * d6
                    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
                        t = d2 / (d2 - d6)
                        bary = vec3(1.0 - t, 0.0, t)
                        feature = EDGE_CA
                    else:
                        va = d3 * d6 - d5 * d4
                        if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
                            t = (d4 - d3) / ((d4 - d3) + (d5 - d6))
                            bary = vec3(0.0, 1.0 - t, t)
                            feature = EDGE_BC
                        else:
                            denom = 1.0 / (va + vb + vc)
                            v = vb * denom
                            w = vc * denom
                            bary = vec3(1.0 - v - w, v, w)
                            feature = FACE
    return bary, feature


@ti.kernel
def closest_points(p: nd_vec3, a: nd_vec3, b: nd_vec3, c: nd_vec3, bary: nd_vec3, feature: nd_i32):
    """Vectorised :func:`closest_point_on_triangle` (row k: point p[k], triangle a[k] b[k] c[k])."""
    for k in p:
        bk, fk = closest_point_on_triangle(p[k], a[k], b[k], c[k])
        bary[k] = bk
        feature[k] = fk
