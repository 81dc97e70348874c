/* What Fortran cannot ask the system: the kind and 64-bit size of a file (a FIFO given as a
 * mesh would block a reader forever), and the machine's memory (to refuse a model that
 * cannot fit before allocating it). Called from casca_files (src/base/files.f90). */
#include <sys/stat.h>
#include <unistd.h>

/* 0: missing, 1: regular file, 2: folder, 3: anything else (FIFO, device, socket) */
int casca_file_kind(const char *path, long long *size)
{
    struct stat st;
    *size = 0;
    if (stat(path, &st) != 0)
        return 0;
    *size = (long long)st.st_size;
    if (S_ISREG(st.st_mode))
        return 1;
    if (S_ISDIR(st.st_mode))
        return 2;
    return 3;
}

/* bytes of physical memory (0 if unknown) */
long long casca_physical_memory(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    return pages > 0 && page > 0 ? (long long)pages * page : 0;
}
