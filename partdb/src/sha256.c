// sha256.c: the checksum of stored glTF and model bytes, by OpenSSL's
// libcrypto (its SHA-256 uses the CPU's SHA extensions where there are any:
// about six times the hand-written one this replaced, on the kiosk's every
// load of its parts and model).
#include <openssl/evp.h>
#include <stdbool.h>
#include <stdio.h>

#include "sp/partdb.h"

bool sp_sha256_hex(const void* data, size_t size, char hex[65])
{
    unsigned char md[EVP_MAX_MD_SIZE];
    unsigned int n = 0;
    hex[0] = 0;
    if (!EVP_Digest(data, size, md, &n, EVP_sha256(), NULL) || n != 32) return false;
    for (unsigned int i = 0; i < n; ++i)
        snprintf(hex + 2 * i, 3, "%02x", md[i]);
    return true;
}
