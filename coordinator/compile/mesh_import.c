/* mesh_import.c -- Assimp imports in a child process (see mesh_import.h). */
#include "compile/mesh_import.h"

#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "compile/confine.h"
#include "file.h"
#include "compile/plyhead.h"
#include "clock.h"
#include "compile/rlimit.h"

#define BUDGET_BASE ((size_t)256 << 20)   /* address space for an import, plus ... */
#define BUDGET_PER_BYTE 64                 /* ... this much per byte of the file */
#define MAX_MATERIALS (1u << 20)

/* ---- converting Assimp's scene (in the child) ---- */

static int grow_mesh(mesh_data *m, uint32_t nv, uint32_t nt, int normals, int uvs)
{
    if ((m->pos = realloc(m->pos, (size_t)nv * sizeof *m->pos)) == NULL ||
        (m->tri = realloc(m->tri, (size_t)nt * sizeof *m->tri)) == NULL ||
        (m->tri_flags = realloc(m->tri_flags, nt ? nt : 1)) == NULL ||
        (m->tri_mat = realloc(m->tri_mat, (size_t)nt * sizeof *m->tri_mat)) == NULL)
        return -1;
    if (normals && (m->nrm = realloc(m->nrm, (size_t)nv * sizeof *m->nrm)) == NULL)
        return -1;
    if (uvs && (m->uv = realloc(m->uv, (size_t)nv * sizeof *m->uv)) == NULL)
        return -1;
    return 0;
}

static void assimp_material(const struct aiMaterial *am, mesh_material *o)
{
    struct aiColor4D c;
    float f;
    unsigned int one = 1;
    memset(o, 0, sizeof *o);
    o->kd = v3s(0.8f);
    o->tf = v3s(1.0f);
    o->ni = 1.5f;
    o->d = 1.0f;
    o->illum = 1;
    o->defined = 1;
    if (!am)
        return;
    if (aiGetMaterialColor(am, AI_MATKEY_COLOR_DIFFUSE, &c) == aiReturn_SUCCESS)
        o->kd = v3(c.r, c.g, c.b);
    if (aiGetMaterialColor(am, AI_MATKEY_COLOR_SPECULAR, &c) == aiReturn_SUCCESS)
        o->ks = v3(c.r, c.g, c.b);
    if (aiGetMaterialColor(am, AI_MATKEY_COLOR_EMISSIVE, &c) == aiReturn_SUCCESS)
        o->ke = v3(c.r, c.g, c.b);
    if (aiGetMaterialFloatArray(am, AI_MATKEY_SHININESS, &f, &one) == aiReturn_SUCCESS)
        o->ns = f;
    one = 1;
    if (aiGetMaterialFloatArray(am, AI_MATKEY_REFRACTI, &f, &one) == aiReturn_SUCCESS)
        o->ni = f;
    /* Negative or non-finite values from a file are not colours. */
    vec3 *cols[] = {&o->kd, &o->ks, &o->ke};
    for (int i = 0; i < 3; i++)
        if (!(cols[i]->x >= 0.0f && cols[i]->y >= 0.0f && cols[i]->z >= 0.0f) || !isfinite(v3_max(*cols[i])))
            *cols[i] = v3s(0.0f);
    if (!(o->ns >= 0.0f && o->ns <= 1.0e6f))
        o->ns = 0.0f;
    if (!isfinite(o->ni))
        o->ni = 1.5f;
    o->illum = v3_is_zero(o->ks) ? 1 : 2;
}

/* An imported scene, flattened (node transforms applied) into one indexed
 * mesh; points and lines are dropped. */
static int convert(const struct aiScene *sc, const char *path, mesh_data *m, fr_error *err)
{
    memset(m, 0, sizeof *m);
    int rc = 0;
    uint32_t nv = 0, nt = 0;
    int normals = 0, uvs = 0;
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        const struct aiMesh *am = sc->mMeshes[i];
        if ((uint64_t)nv + am->mNumVertices > 0x7fffffffu || (uint64_t)nt + am->mNumFaces > 0x7fffffffu) {
            rc = fr_fail(err, "%s: too many vertices or faces", path);
            break;
        }
        nv += am->mNumVertices;
        nt += am->mNumFaces;
        normals |= am->mNormals != NULL;
        uvs |= am->mTextureCoords[0] != NULL;
    }
    m->n_mats = sc->mNumMaterials ? sc->mNumMaterials : 1;
    if (rc == 0 && ((m->mats = calloc(m->n_mats, sizeof *m->mats)) == NULL ||
                    grow_mesh(m, nv ? nv : 1, nt ? nt : 1, normals, uvs) < 0))
        rc = fr_fail(err, "%s: out of memory", path);
    for (unsigned i = 0; rc == 0 && i < m->n_mats; i++) {
        if (i < sc->mNumMaterials)
            assimp_material(sc->mMaterials[i], &m->mats[i]);
        else
            assimp_material(NULL, &m->mats[i]);
        struct aiString name;
        if (i < sc->mNumMaterials && aiGetMaterialString(sc->mMaterials[i], AI_MATKEY_NAME, &name) == aiReturn_SUCCESS)
            snprintf(m->mats[i].name, sizeof m->mats[i].name, "%s", name.data);
    }
    for (unsigned i = 0; rc == 0 && i < sc->mNumMeshes; i++) {
        const struct aiMesh *am = sc->mMeshes[i];
        uint32_t base = m->n_vert;
        for (unsigned v = 0; v < am->mNumVertices; v++) {
            const struct aiVector3D *p = &am->mVertices[v];
            m->pos[base + v] = v3(p->x, p->y, p->z);
            if (normals)
                m->nrm[base + v] = am->mNormals ? v3(am->mNormals[v].x, am->mNormals[v].y, am->mNormals[v].z)
                                                : v3s(0.0f);
            if (uvs)
                m->uv[base + v] = am->mTextureCoords[0]
                                      ? (vec2){am->mTextureCoords[0][v].x, am->mTextureCoords[0][v].y}
                                      : (vec2){0.0f, 0.0f};
            if (!isfinite(m->pos[base + v].x) || !isfinite(m->pos[base + v].y) || !isfinite(m->pos[base + v].z))
                rc = fr_fail(err, "%s: mesh %u vertex %u is not finite", path, i, v);
        }
        m->n_vert += am->mNumVertices;
        for (unsigned f = 0; rc == 0 && f < am->mNumFaces; f++) {
            const struct aiFace *fc = &am->mFaces[f];
            if (fc->mNumIndices != 3)
                continue;
            uint32_t t = m->n_tri++;
            for (int k = 0; k < 3; k++) {
                if (fc->mIndices[k] >= am->mNumVertices) {
                    rc = fr_fail(err, "%s: mesh %u face %u: index out of range", path, i, f);
                    break;
                }
                m->tri[t][k] = base + fc->mIndices[k];
            }
            m->tri_flags[t] = (uint8_t)((am->mNormals ? FR_TRI_NORMALS : 0) | (am->mTextureCoords[0] ? FR_TRI_UVS : 0));
            m->tri_mat[t] = am->mMaterialIndex < m->n_mats ? am->mMaterialIndex : 0;
        }
    }
    if (rc == 0 && m->n_tri == 0)
        rc = fr_fail(err, "%s: no triangles", path);
    if (rc < 0)
        mesh_data_free(m);
    return rc;
}

/* ---- the files Assimp opens: regular ones only (in the child) ---- */

typedef struct { FILE *f; size_t size; } io_handle;

static char open_refused[sizeof ((fr_error *)0)->msg];   /* why the last refused open was refused */
static const confine *io_scope;                          /* where every file Assimp opens must lie */

static io_handle *handle(struct aiFile *f) { return (io_handle *)(void *)f->UserData; }

static size_t io_read(struct aiFile *f, char *buf, size_t size, size_t count)
{
    return size && count ? fread(buf, size, count, handle(f)->f) : 0;
}

static size_t io_write(struct aiFile *f, const char *buf, size_t size, size_t count)
{
    (void)f, (void)buf, (void)size, (void)count;
    return 0;
}

static size_t io_tell(struct aiFile *f)
{
    off_t at = ftello(handle(f)->f);
    return at < 0 ? 0 : (size_t)at;
}

static size_t io_size(struct aiFile *f) { return handle(f)->size; }

static void io_flush(struct aiFile *f) { (void)f; }

static enum aiReturn io_seek(struct aiFile *f, size_t off, enum aiOrigin from)
{
    int whence = from == aiOrigin_SET ? SEEK_SET : from == aiOrigin_CUR ? SEEK_CUR : SEEK_END;
    if (off > (size_t)INT64_MAX)
        return aiReturn_FAILURE;
    return fseeko(handle(f)->f, (off_t)off, whence) == 0 ? aiReturn_SUCCESS : aiReturn_FAILURE;
}

static struct aiFile *io_open(struct aiFileIO *io, const char *name, const char *mode)
{
    (void)io;
    if (strpbrk(mode, "wa+"))
        return NULL;
    int fd;
    size_t size;
    fr_error e;
    if (confine_open(io_scope, name, MESH_IMPORT_MAX_BYTES, &fd, &size, &e) < 0) {
        snprintf(open_refused, sizeof open_refused, "%s", e.msg);
        return NULL;
    }
    struct aiFile *f = calloc(1, sizeof *f);
    io_handle *h = calloc(1, sizeof *h);
    FILE *s = fdopen(fd, "rb");
    if (!f || !h || !s) {
        free(f);
        free(h);
        if (s)
            fclose(s);
        else
            close(fd);
        return NULL;
    }
    h->f = s;
    h->size = size;
    *f = (struct aiFile){io_read, io_write, io_tell, io_size, io_seek, io_flush, (aiUserData)(void *)h};
    return f;
}

static void io_close(struct aiFileIO *io, struct aiFile *f)
{
    (void)io;
    if (!f)
        return;
    fclose(handle(f)->f);
    free(handle(f));
    free(f);
}

/* ---- the pipe between child and parent ----
 *
 * The child sends MAGIC, then either 1, a length and an error message, or
 * 0, the counts (vertices, triangles, materials, 1 if normals, 1 if UVs)
 * and the arrays of the mesh_data in their order in memory (same program,
 * same layout).  The parent checks every count and index as if the bytes
 * came from a file. */

#define MAGIC 0x494d5246u   /* "FRMI" */

static void send_error(int fd, const fr_error *e)
{
    uint32_t head[3] = {MAGIC, 1, (uint32_t)strlen(e->msg)};
    if (file_write_all(fd, head, sizeof head) == 0)
        file_write_all(fd, e->msg, head[2]);
}

static void send_mesh(int fd, const mesh_data *m)
{
    uint32_t head[7] = {MAGIC, 0, m->n_vert, m->n_tri, m->n_mats, m->nrm != NULL, m->uv != NULL};
    size_t nv = m->n_vert, nt = m->n_tri;
    if (file_write_all(fd, head, sizeof head) < 0 ||
        file_write_all(fd, m->mats, m->n_mats * sizeof *m->mats) < 0 ||
        file_write_all(fd, m->pos, nv * sizeof *m->pos) < 0 ||
        (m->nrm && file_write_all(fd, m->nrm, nv * sizeof *m->nrm) < 0) ||
        (m->uv && file_write_all(fd, m->uv, nv * sizeof *m->uv) < 0) ||
        file_write_all(fd, m->tri, nt * sizeof *m->tri) < 0 || file_write_all(fd, m->tri_flags, nt) < 0)
        return;
    file_write_all(fd, m->tri_mat, nt * sizeof *m->tri_mat);
}

/* The child's whole life: limits, the import, the answer. */
static void child(const char *path, const confine *scope, size_t size, int out)
{
    io_scope = scope;
    /* Assimp prints its assertion failures and logs: the parent's message
     * says what happened. */
    int null = open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (null >= 0) {
        dup2(null, STDERR_FILENO);
        close(null);
    }
    /* Address space: what the process maps already plus the import's
     * budget; a minute of CPU and one more second a MiB. */
    uint64_t cpu = 60 + size / ((size_t)1 << 20);
    rlimit_child(BUDGET_BASE + (uint64_t)BUDGET_PER_BYTE * size, cpu, cpu);

    struct aiFileIO io = {io_open, io_close, NULL};
    const struct aiScene *sc = aiImportFileEx(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                                        aiProcess_PreTransformVertices | aiProcess_SortByPType,
                                              &io);
    fr_error e;
    mesh_data m;
    memset(&m, 0, sizeof m);
    if (!sc) {
        const char *why = aiGetErrorString();
        if (open_refused[0])
            fr_fail(&e, "%s: %s", path, open_refused);
        else if (strstr(why, "bad_alloc"))
            fr_fail(&e, "%s: the mesh importer (Assimp) ran out of its %zu MiB of memory (does the file declare "
                    "more than it holds?)", path, (BUDGET_BASE + BUDGET_PER_BYTE * size) >> 20);
        else
            /* Assimp's messages quote tokens of the file: only the words
             * before the first quote are its own. */
            fr_fail(&e, "%s: the mesh importer (Assimp) cannot read it: %.*s", path, (int)strcspn(why, "'\"`"), why);
        send_error(out, &e);
    } else if (convert(sc, path, &m, &e) < 0) {
        send_error(out, &e);
    } else {
        send_mesh(out, &m);
    }
}

enum { GOT = 0, SHORT = -1, LATE = -2 };

/* Read exactly n bytes before `deadline` (clock_now() seconds). */
static int read_all(int fd, void *buf, size_t n, double deadline)
{
    char *p = buf;
    while (n) {
        double left = deadline - clock_now();
        if (left <= 0)
            return LATE;
        struct pollfd pf = {fd, POLLIN, 0};
        int ready = poll(&pf, 1, left > 1e6 ? 1000000000 : (int)(left * 1000) + 1);
        if (ready < 0 && errno == EINTR)
            continue;
        if (ready == 0)
            continue;
        if (ready < 0)
            return SHORT;
        ssize_t r = read(fd, p, n);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            return SHORT;
        p += r;
        n -= (size_t)r;
    }
    return GOT;
}

/* The child's answer into m (or err): GOT with 0 in *rc, GOT with -1 and
 * err set (the child's error, or a malformed answer), SHORT or LATE. */
static int receive(int fd, const char *path, size_t budget, double deadline, mesh_data *m, int *rc, fr_error *err)
{
    uint32_t head[2];
    int got = read_all(fd, head, sizeof head, deadline);
    if (got != GOT)
        return got;
    *rc = -1;
    if (head[0] != MAGIC || head[1] > 1) {
        fr_fail(err, "%s: the mesh importer answered garbage", path);
        return GOT;
    }
    if (head[1] == 1) {
        uint32_t len;
        char msg[sizeof err->msg];
        if ((got = read_all(fd, &len, sizeof len, deadline)) != GOT)
            return got;
        if (len >= sizeof msg) {
            fr_fail(err, "%s: the mesh importer answered garbage", path);
            return GOT;
        }
        if ((got = read_all(fd, msg, len, deadline)) != GOT)
            return got;
        msg[len] = 0;
        fr_fail(err, "%s", msg);
        return GOT;
    }
    uint32_t c[5];
    if ((got = read_all(fd, c, sizeof c, deadline)) != GOT)
        return got;
    size_t nv = c[0], nt = c[1], nm = c[2];
    size_t bytes = nm * sizeof *m->mats + nv * (sizeof *m->pos + (c[3] ? sizeof *m->nrm : 0) + (c[4] ? sizeof *m->uv : 0)) +
                   nt * (sizeof *m->tri + 1 + sizeof *m->tri_mat);
    if (nv > 0x7fffffffu || nt == 0 || nt > 0x7fffffffu || nm == 0 || nm > MAX_MATERIALS || c[3] > 1 || c[4] > 1 ||
        bytes > budget) {
        fr_fail(err, "%s: the mesh importer answered garbage", path);
        return GOT;
    }
    memset(m, 0, sizeof *m);
    m->mats = malloc(nm * sizeof *m->mats);
    m->pos = malloc(nv ? nv * sizeof *m->pos : 1);
    m->nrm = c[3] ? malloc(nv ? nv * sizeof *m->nrm : 1) : NULL;
    m->uv = c[4] ? malloc(nv ? nv * sizeof *m->uv : 1) : NULL;
    m->tri = malloc(nt * sizeof *m->tri);
    m->tri_flags = malloc(nt);
    m->tri_mat = malloc(nt * sizeof *m->tri_mat);
    m->n_mats = (uint32_t)nm;
    if (!m->mats || !m->pos || (c[3] && !m->nrm) || (c[4] && !m->uv) || !m->tri || !m->tri_flags || !m->tri_mat) {
        mesh_data_free(m);
        fr_fail(err, "%s: out of memory", path);
        return GOT;
    }
    if ((got = read_all(fd, m->mats, nm * sizeof *m->mats, deadline)) != GOT ||
        (got = read_all(fd, m->pos, nv * sizeof *m->pos, deadline)) != GOT ||
        (c[3] && (got = read_all(fd, m->nrm, nv * sizeof *m->nrm, deadline)) != GOT) ||
        (c[4] && (got = read_all(fd, m->uv, nv * sizeof *m->uv, deadline)) != GOT) ||
        (got = read_all(fd, m->tri, nt * sizeof *m->tri, deadline)) != GOT ||
        (got = read_all(fd, m->tri_flags, nt, deadline)) != GOT ||
        (got = read_all(fd, m->tri_mat, nt * sizeof *m->tri_mat, deadline)) != GOT) {
        mesh_data_free(m);
        return got;
    }
    m->n_vert = (uint32_t)nv;
    m->n_tri = (uint32_t)nt;
    /* Checked again here: the child ran code the file could subvert. */
    for (size_t i = 0; i < nm; i++)
        m->mats[i].name[sizeof m->mats[i].name - 1] = 0;
    for (size_t i = 0; i < nv; i++)
        if (!isfinite(m->pos[i].x) || !isfinite(m->pos[i].y) || !isfinite(m->pos[i].z) ||
            (m->nrm && !(isfinite(m->nrm[i].x) && isfinite(m->nrm[i].y) && isfinite(m->nrm[i].z))) ||
            (m->uv && !(isfinite(m->uv[i].u) && isfinite(m->uv[i].v))))
            nt = 0;
    for (size_t t = 0; t < nt; t++)
        if (m->tri[t][0] >= nv || m->tri[t][1] >= nv || m->tri[t][2] >= nv || m->tri_mat[t] >= nm ||
            (m->tri_flags[t] & ~(FR_TRI_NORMALS | FR_TRI_UVS)) || ((m->tri_flags[t] & FR_TRI_NORMALS) && !m->nrm) ||
            ((m->tri_flags[t] & FR_TRI_UVS) && !m->uv))
            nt = 0;
    if (nt == 0) {
        mesh_data_free(m);
        fr_fail(err, "%s: the mesh importer answered garbage", path);
        return GOT;
    }
    *rc = 0;
    return GOT;
}

/* The file is a regular file of at most MESH_IMPORT_MAX_BYTES (*size), and
 * a PLY header in it declares no more than the file can hold. */
static int check_header(const char *path, const confine *scope, size_t *size, fr_error *err)
{
    int fd;
    if (confine_open(scope, path, MESH_IMPORT_MAX_BYTES, &fd, size, err) < 0)
        return -1;
    char *head = malloc(PLY_HEADER_MAX);
    if (!head) {
        close(fd);
        return fr_fail(err, "%s: out of memory", path);
    }
    size_t got = 0;
    while (got < PLY_HEADER_MAX) {
        ssize_t k = read(fd, head + got, PLY_HEADER_MAX - got);
        if (k < 0 && errno == EINTR)
            continue;
        if (k < 0) {
            int e = errno;
            free(head);
            close(fd);
            return fr_fail(err, "%s: read error: %s", path, strerror(e));
        }
        if (k == 0)
            break;
        got += (size_t)k;
    }
    close(fd);
    int rc = plyhead_check(path, head, got, *size, err);
    free(head);
    return rc;
}

int mesh_import(const char *path, const confine *scope, mesh_data *m, fr_error *err)
{
    memset(m, 0, sizeof *m);
    confine own;
    if (!scope) {
        if (confine_init(&own, path, NULL, 0, err) < 0)
            return -1;
        scope = &own;
    }
    size_t size;
    if (check_header(path, scope, &size, err) < 0)
        return -1;
    int p[2];
    if (pipe2(p, O_CLOEXEC) < 0)
        return fr_fail(err, "%s: cannot start the mesh importer: %s", path, strerror(errno));
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0) {
        int e = errno;
        close(p[0]);
        close(p[1]);
        return fr_fail(err, "%s: cannot start the mesh importer: %s", path, strerror(e));
    }
    if (pid == 0) {
        close(p[0]);
        child(path, scope, size, p[1]);
        _exit(0);
    }
    close(p[1]);
    /* Wall time: the CPU limit's, twice over, for a loaded machine or a
     * child blocked on something that is not a regular file. */
    double limit = 2.0 * (double)(60 + size / ((size_t)1 << 20));
    int rc = -1;
    int got = receive(p[0], path, BUDGET_BASE + BUDGET_PER_BYTE * size, clock_now() + limit, m, &rc, err);
    close(p[0]);
    if (got == LATE)
        kill(pid, SIGKILL);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (got == GOT)
        return rc;
    if (got == LATE)
        return fr_fail(err, "%s: the mesh importer (Assimp) took more than %.0f s", path, limit);
    if (WIFSIGNALED(status)) {
        int sig = WTERMSIG(status);
        if (sig == SIGXCPU)
            return fr_fail(err, "%s: the mesh importer (Assimp) used more than its %zu s of CPU time", path,
                           (size_t)(60 + size / ((size_t)1 << 20)));
        return fr_fail(err, "%s: the mesh importer (Assimp) crashed (signal %d: %s); the file is malformed, or needs "
                       "more than the importer's %zu MiB of memory", path, sig, strsignal(sig),
                       (BUDGET_BASE + BUDGET_PER_BYTE * size) >> 20);
    }
    return fr_fail(err, "%s: the mesh importer (Assimp) stopped without an answer (exit status %d)", path,
                   WIFEXITED(status) ? WEXITSTATUS(status) : -1);
}
