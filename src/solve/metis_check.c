/* metis_graph.f90 passes METIS 32-bit integers (integer(c_int)) and no reals: a METIS built
 * with a 64-bit idx_t would read them as garbage, so the build stops here instead. */
#include <metis.h>

_Static_assert(IDXTYPEWIDTH == 32, "casca needs METIS built with a 32-bit idx_t (IDXTYPEWIDTH 32)");

/* The METIS version casca was built against (casca --version): metis.h's own numbers, as the
 * library has no call that tells them. */
void casca_metis_version(int *major, int *minor, int *subminor)
{
  *major = METIS_VER_MAJOR;
  *minor = METIS_VER_MINOR;
  *subminor = METIS_VER_SUBMINOR;
}
