// plugin.c: loading a black-box rig from a shared object with dlopen/dlsym
// of its one entry symbol (SP_BLACKBOX_ENTRY).
#include "sp/plugin.h"

#include <dlfcn.h>
#include <elf.h>
#include <errno.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

static void unload(void* dl)
{
    dlclose(dl);
}

// ELF fields in either byte order, so a foreign object is still checked
// rather than misread; dlopen then refuses it with its own reason.
static uint64_t elf_get(const unsigned char* p, int n, int big)
{
    uint64_t v = 0;
    for (int i = 0; i < n; i++)
        v |= (uint64_t)p[big ? i : n - 1 - i] << (8 * (n - 1 - i));
    return v;
}

#if defined(__x86_64__)
#define SP_HOST_MACHINE EM_X86_64
#elif defined(__aarch64__)
#define SP_HOST_MACHINE EM_AARCH64
#elif defined(__i386__)
#define SP_HOST_MACHINE EM_386
#elif defined(__arm__)
#define SP_HOST_MACHINE EM_ARM
#elif defined(__riscv)
#define SP_HOST_MACHINE EM_RISCV
#elif defined(__powerpc64__)
#define SP_HOST_MACHINE EM_PPC64
#else
#define SP_HOST_MACHINE EM_NONE // unknown here: left to dlopen
#endif

static const char* machine_name(unsigned m, char* buf, size_t size)
{
    switch (m) {
    case EM_X86_64:
        return "x86-64";
    case EM_AARCH64:
        return "AArch64";
    case EM_386:
        return "x86 (32-bit)";
    case EM_ARM:
        return "ARM (32-bit)";
    case EM_RISCV:
        return "RISC-V";
    case EM_PPC64:
        return "PowerPC 64";
    default:
        snprintf(buf, size, "ELF machine %u", m);
        return buf;
    }
}

// Does [off, off + len) lie within a file of `size` bytes (without overflow)?
static int elf_within(uint64_t off, uint64_t len, uint64_t size)
{
    return off <= size && len <= size - off;
}

// dlopen maps segments with mmap, and touching a page past the end of a
// truncated file raises SIGBUS instead of returning an error; so check the
// tables and PT_LOAD segments lie within the file first. Files that are not
// ELF at all are left to dlopen, which rejects them cleanly.
static sp_result check_elf_complete(const char* path, uint64_t size, sp_error* err)
{
    FILE* f = fopen(path, "rb");
    if (!f) return sp_fail(err, SP_ERR_IO, "%s: %s", path, strerror(errno));
    unsigned char h[sizeof(Elf64_Ehdr)] = {0};
    size_t got = fread(h, 1, sizeof h, f);
    if (got < SELFMAG || memcmp(h, ELFMAG, SELFMAG) != 0) {
        fclose(f);
        return SP_OK;
    }
    sp_result r = SP_OK;
    int cls = got > EI_CLASS ? h[EI_CLASS] : 0, data = got > EI_DATA ? h[EI_DATA] : 0;
    if (got < EI_NIDENT) goto truncated;
    if (cls != ELFCLASS32 && cls != ELFCLASS64) {
        r = sp_fail(err, SP_ERR_PARSE, "%s: ELF class %d is neither 32- nor 64-bit (not a shared object)", path, cls);
        goto done;
    }
    if (data != ELFDATA2LSB && data != ELFDATA2MSB) {
        r = sp_fail(err, SP_ERR_PARSE, "%s: ELF byte order %d is unknown (not a shared object)", path, data);
        goto done;
    }
    int w = cls == ELFCLASS64, big = data == ELFDATA2MSB;
    if (got < (w ? sizeof(Elf64_Ehdr) : sizeof(Elf32_Ehdr))) goto truncated;
    // dlopen says "No such file or directory" for another machine's object.
    unsigned machine = (unsigned)elf_get(h + offsetof(Elf64_Ehdr, e_machine), 2, big); // same offset in both classes
    if (SP_HOST_MACHINE != EM_NONE && machine != SP_HOST_MACHINE) {
        char a[32], b[32];
        r = sp_fail(err, SP_ERR_PARSE, "%s: built for another processor (%s), this is %s", path,
                    machine_name(machine, a, sizeof a), machine_name(SP_HOST_MACHINE, b, sizeof b));
        goto done;
    }
    // Offsets of the header fields, from <elf.h>'s layouts.
    uint64_t phoff = w ? elf_get(h + offsetof(Elf64_Ehdr, e_phoff), 8, big) : elf_get(h + offsetof(Elf32_Ehdr, e_phoff), 4, big);
    uint64_t shoff = w ? elf_get(h + offsetof(Elf64_Ehdr, e_shoff), 8, big) : elf_get(h + offsetof(Elf32_Ehdr, e_shoff), 4, big);
    uint64_t phentsize = elf_get(h + (w ? offsetof(Elf64_Ehdr, e_phentsize) : offsetof(Elf32_Ehdr, e_phentsize)), 2, big);
    uint64_t phnum = elf_get(h + (w ? offsetof(Elf64_Ehdr, e_phnum) : offsetof(Elf32_Ehdr, e_phnum)), 2, big);
    uint64_t shentsize = elf_get(h + (w ? offsetof(Elf64_Ehdr, e_shentsize) : offsetof(Elf32_Ehdr, e_shentsize)), 2, big);
    uint64_t shnum = elf_get(h + (w ? offsetof(Elf64_Ehdr, e_shnum) : offsetof(Elf32_Ehdr, e_shnum)), 2, big);
    size_t phsize = w ? sizeof(Elf64_Phdr) : sizeof(Elf32_Phdr);
    if (phnum && phentsize < phsize) {
        r = sp_fail(err, SP_ERR_PARSE, "%s: ELF program headers of %llu bytes are too small (not a shared object)", path,
                    (unsigned long long)phentsize);
        goto done;
    }
    if (!elf_within(phoff, phnum * phentsize, size)) goto truncated;
    if (shoff != 0 && !elf_within(shoff, shnum * shentsize, size)) goto truncated;
    for (uint64_t i = 0; i < phnum; i++) {
        unsigned char ph[sizeof(Elf64_Phdr)];
        if (fseeko(f, (off_t)(phoff + i * phentsize), SEEK_SET) != 0 || fread(ph, 1, phsize, f) != phsize) goto truncated;
        uint64_t type = elf_get(ph + (w ? offsetof(Elf64_Phdr, p_type) : offsetof(Elf32_Phdr, p_type)), 4, big);
        if (type != PT_LOAD) continue;
        uint64_t off =
            w ? elf_get(ph + offsetof(Elf64_Phdr, p_offset), 8, big) : elf_get(ph + offsetof(Elf32_Phdr, p_offset), 4, big);
        uint64_t len =
            w ? elf_get(ph + offsetof(Elf64_Phdr, p_filesz), 8, big) : elf_get(ph + offsetof(Elf32_Phdr, p_filesz), 4, big);
        if (!elf_within(off, len, size)) goto truncated;
    }
    goto done;
truncated:
    r = sp_fail(err, SP_ERR_PARSE, "%s: not a complete shared object (truncated?)", path);
done:
    fclose(f);
    return r;
}

sp_result sp_blackbox_load_plugin(const char* path, sp_blackbox** out, sp_error* err)
{
    *out = NULL;
    struct stat st;
    if (stat(path, &st) != 0) return sp_fail(err, SP_ERR_IO, "%s: %s", path, strerror(errno));
    if (S_ISDIR(st.st_mode)) return sp_fail(err, SP_ERR_IO, "%s: is a directory, not a plugin", path);
    // Opening a named pipe waits for a writer forever (as would dlopen), and
    // a device has no end: a plugin is a regular file.
    if (!S_ISREG(st.st_mode)) return sp_fail(err, SP_ERR_IO, "%s: not a regular file", path);
    // A bare file name would make dlopen search the library path instead of
    // loading the file the user named.
    char local[4096];
    const char* file = path;
    if (!strchr(path, '/')) {
        snprintf(local, sizeof local, "./%s", path);
        file = local;
    }
    sp_result r = check_elf_complete(path, (uint64_t)st.st_size, err);
    if (r != SP_OK) return r;
    dlerror();
    void* dl = dlopen(file, RTLD_NOW | RTLD_LOCAL);
    if (!dl) {
        const char* why = dlerror();
        return sp_fail(err, SP_ERR_PARSE, "%s: cannot load it as a shared object (%s)", path, why ? why : "unknown reason");
    }
    dlerror();
    void* sym = dlsym(dl, SP_BLACKBOX_ENTRY);
    if (!sym) {
        dlclose(dl);
        return sp_fail(err, SP_ERR_INVALID,
                       "%s: no symbol %s (not a sketchpose black-box plugin; the entry must be exported with C linkage, "
                       "extern \"C\" in C++, and default visibility)",
                       path, SP_BLACKBOX_ENTRY);
    }
    // ISO C has no cast from an object pointer to a function pointer; POSIX
    // guarantees the representation is the same.
    sp_blackbox_entry_fn entry;
    memcpy(&entry, &sym, sizeof entry);
    const sp_blackbox_rig* rig = entry();
    if (!rig) {
        dlclose(dl);
        return sp_fail(err, SP_ERR_INVALID, "%s: %s() returned no rig", path, SP_BLACKBOX_ENTRY);
    }
    r = sp_blackbox_open(rig, path, out, err);
    if (r != SP_OK) {
        dlclose(dl);
        return r;
    }
    sp_blackbox_on_destroy(*out, unload, dl);
    return SP_OK;
}
