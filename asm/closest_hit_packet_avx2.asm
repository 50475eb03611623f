; Closest hits of 8 rays, one per lane, against a run of spheres, one sphere
; per step broadcast to every lane (AVX2). Each lane computes exactly what
; ptr_closest_hit_c computes for its ray, in the same order and with the same
; IEEE operations (the arithmetic macros are the one-ray kernels'), and the
; spheres come in index order with a strict <, so the lowest index wins ties
; as there: the answers are bit-identical to ptr_closest_hit_packet_c's.

%include "ptr.inc"
%include "layout.inc"
%include "sphere_math.inc"

section .rodata
align 32
ones:      times 8 dd 1
sign_mask: times 8 dd 0x80000000

section .text

; void ptr_closest_hit_packet_avx2(const PtrRayPacket *rays,
;                                  const PtrSpheres *spheres, size_t count,
;                                  PtrHitPacket *hits);
;
; rdi rays, rsi spheres, rdx count, rcx hits (moved to rsi)
; r8 cx, r9 cy, r10 cz, r11 radius, rax sphere index
; ymm0-2 dx, dy, dz   ymm3 tmin   ymm4 best t   ymm5 best index
; ymm6 rax in every lane   ymm7 sign mask   ymm15 ones   ymm8-14 scratch
FUNCTION ptr_closest_hit_packet_avx2
    LOAD_SPHERE_POINTERS
    vmovaps     ymm0, [rdi + PACKET_DIR_X]
    vmovaps     ymm1, [rdi + PACKET_DIR_Y]
    vmovaps     ymm2, [rdi + PACKET_DIR_Z]
    vmovaps     ymm3, [rdi + PACKET_TMIN]
    vmovaps     ymm4, [rdi + PACKET_TMAX]
    vpcmpeqd    ymm5, ymm5, ymm5                ; PTR_NO_HIT in every lane
    vpxor       ymm6, ymm6, ymm6
    vmovups     ymm7, [sign_mask]
    vmovdqu     ymm15, [ones]
    xor         eax, eax
.sphere:
    cmp         rax, rdx
    jae         .done
    vbroadcastss ymm12, [r8 + rax*4]
    vmovaps     ymm8, [rdi + PACKET_ORG_X]
    vsubps      ymm8, ymm8, ymm12               ; fx = ox - cx
    vbroadcastss ymm12, [r9 + rax*4]
    vmovaps     ymm9, [rdi + PACKET_ORG_Y]
    vsubps      ymm9, ymm9, ymm12               ; fy
    vbroadcastss ymm12, [r10 + rax*4]
    vmovaps     ymm10, [rdi + PACKET_ORG_Z]
    vsubps      ymm10, ymm10, ymm12             ; fz
    DISCRIMINANT y, vbroadcastss
    vxorps      ymm14, ymm14, ymm14
    vcmpps      ymm14, ymm12, ymm14, CMP_GE_OQ  ; disc >= 0 (NaN radius: no)
    vtestps     ymm14, ymm14
    jz          .next                           ; no lane can hit: skip sqrt, div
    ROOT_AVX2
    KEEP_NEARER_AVX2
.next:
    vpaddd      ymm6, ymm6, ymm15
    inc         rax
    jmp         .sphere
.done:
    vmovaps     [rsi + HITS_T], ymm4
    vmovdqa     [rsi + HITS_SPHERE], ymm5
    vzeroupper
    ret

section .note.GNU-stack noalloc noexec nowrite progbits
