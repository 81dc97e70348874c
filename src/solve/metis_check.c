/* metis_graph.f90 passes METIS 32-bit integers (integer(c_int)) and no reals: a METIS built
 * with a 64-bit idx_t would read them as garbage, so the build stops here instead. */
#include <metis.h>

_Static_assert(IDXTYPEWIDTH == 32, "casca needs METIS built with a 32-bit idx_t (IDXTYPEWIDTH 32)");
