/* What Fortran cannot ask or tell the system: the kind and 64-bit size of a file (a FIFO given
 * as a mesh would block a reader forever) and the machine's memory (to refuse a model that
 * cannot fit before allocating it), called from casca_files (src/base/files.f90); a signal
 * asking the run to stop, from casca_stop_request (src/base/stop_request.f90). */
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

/* A request to stop (SIGTERM, SIGINT, SIGUSR1), kept for the time loop to see at a step's
 * end, where the state is whole: a batch system's time limit then leaves a checkpoint of the
 * last step instead of one up to checkpoint_interval old. A second signal while the first
 * is being served ends the process as if none were caught (Ctrl-C twice). */
#include <signal.h>
#include <string.h>

static volatile sig_atomic_t stop_signal = 0;

static void on_stop(int sig)
{
    if (stop_signal) {
        signal(sig, SIG_DFL);
        raise(sig);
        return;
    }
    stop_signal = sig;
}

void casca_catch_stop(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;   /* a write or an MPI wait under way goes on */
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGUSR1, &sa, NULL);
}

/* the signal caught (0: none) */
int casca_stop_signal(void)
{
    return stop_signal;
}

/* its name as a user knows it, into name (16 characters, NUL-ended): the numbers differ
 * between systems, the macros do not */
void casca_signal_name(int sig, char *name)
{
    const char *s = sig == SIGTERM ? "SIGTERM" : sig == SIGINT ? "SIGINT" :
                    sig == SIGUSR1 ? "SIGUSR1" : "signal";
    strncpy(name, s, 15);
    name[15] = '\0';
}
