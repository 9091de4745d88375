#ifndef hysteron_source_rbsn_cgal_h
#define hysteron_source_rbsn_cgal_h

/**
 * @file
 * CGAL's Delaunay triangulations (the duals of the 2D and 3D Voronoi
 * tessellations) with the exact-predicates kernel. CGAL's headers are not
 * warning-clean under -Wall -Wextra.
 */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#pragma GCC diagnostic pop

#endif
