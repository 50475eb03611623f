; Closest hits of 8 rays in the tree, AVX2: the one-ray AVX2 traversal lane by
; lane. Below AVX-512 a packet walking the tree together does not pay: its
; box tests need a blend per plane and lane where the one-ray traversal has
; one per plane (docs/intersectors.md); the bundles' camera rays ask the
; table for packets at every level, and get this.

%include "ptr.inc"
%include "layout.inc"

extern ptr_bvh_closest_hit_avx2

section .text

; void ptr_bvh_closest_hit_packet_avx2(const PtrRayPacket *rays,
;                                      const PtrBvh *bvh,
;                                      const PtrSpheres *spheres,
;                                      PtrHitPacket *hits);
;
; rbx rays, r12 bvh, r13 spheres, rbp hits, r14 the lane; the lane's PtrRay
; at rsp, its PtrHit at rsp + 32.
FUNCTION ptr_bvh_closest_hit_packet_avx2
    push        rbx
    push        rbp
    push        r12
    push        r13
    push        r14
    sub         rsp, 48                         ; a PtrRay and a PtrHit; rsp 16-aligned
    mov         rbx, rdi
    mov         r12, rsi
    mov         r13, rdx
    mov         rbp, rcx
    xor         r14d, r14d
.lane:
%assign field 0
%rep 8
    mov         eax, [rbx + 32 * field + r14*4]  ; PtrRayPacket's fields in PtrRay's order
    mov         [rsp + 4 * field], eax
%assign field field + 1
%endrep
    mov         rdi, rsp
    mov         rsi, r12
    mov         rdx, r13
    lea         rcx, [rsp + 32]
    call        ptr_bvh_closest_hit_avx2
    mov         eax, [rsp + 32 + HIT_T]
    mov         [rbp + HITS_T + r14*4], eax
    mov         eax, [rsp + 32 + HIT_SPHERE]
    mov         [rbp + HITS_SPHERE + r14*4], eax
    inc         r14d
    cmp         r14d, 8
    jb          .lane
    add         rsp, 48
    pop         r14
    pop         r13
    pop         r12
    pop         rbp
    pop         rbx
    ret

section .note.GNU-stack noalloc noexec nowrite progbits
