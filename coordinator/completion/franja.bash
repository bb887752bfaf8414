# franja.bash -- bash completion for franja and franja-worker.
#
# Installed (make install) as share/bash-completion/completions/franja and
# .../franja-worker, where bash-completion loads it on first use; or load it
# by hand: `. coordinator/completion/franja.bash`.  It needs nothing from the
# bash-completion package.  The options come from the programs' own --help,
# so they are always those of the installed build.
#
#   franja <TAB>                 the commands
#   franja render -<TAB>         render's options (likewise for every command)
#   franja render <TAB>          scene files (.json .gltf .glb .fbin) and directories
#   franja render --tonemap <TAB>  none filmic
#   franja hosts <TAB>           check list clean
#   franja stitch <TAB>          directories (job directories)

# _franja_opts PROGRAM [WORDS...]: the options that `PROGRAM WORDS --help` lists.
_franja_opts()
{
    "$@" --help 2>/dev/null | grep -oE -- '(^|[[:space:][|])--?[A-Za-z][-A-Za-z]*' |
        sed 's/^[^-]*//' | sort -u
}

# _franja_files EXTENSION-PATTERN: files matching it, and directories.
_franja_files()
{
    local cur=$1 pat=$2 IFS=$'\n'
    COMPREPLY+=($(compgen -d -- "$cur"))
    if [ -n "$pat" ]; then
        COMPREPLY+=($(compgen -f -X "!$pat" -- "$cur"))
    else
        COMPREPLY+=($(compgen -f -- "$cur"))
    fi
}

_franja()
{
    local cur=${COMP_WORDS[COMP_CWORD]} prev=""
    [ "$COMP_CWORD" -gt 0 ] && prev=${COMP_WORDS[COMP_CWORD-1]}
    local prog=${COMP_WORDS[0]} cmd="" i
    COMPREPLY=()
    for ((i = 1; i < COMP_CWORD; i++)); do
        case ${COMP_WORDS[i]} in -*) ;; *) cmd=${COMP_WORDS[i]}; break ;; esac
    done
    if [ -z "$cmd" ]; then
        if [[ $cur == -* ]]; then
            COMPREPLY=($(compgen -W "--help --version -V" -- "$cur"))
        else
            COMPREPLY=($(compgen -W "render compile stitch hosts deploy help version" -- "$cur"))
        fi
        return 0
    fi
    case $prev in
    --tonemap) COMPREPLY=($(compgen -W "none filmic" -- "$cur")); return 0 ;;
    --progress) COMPREPLY=($(compgen -W "auto json" -- "$cur")); return 0 ;;
    --exr-compression)
        COMPREPLY=($(compgen -W "none rle zips zip piz pxr24 b44 b44a dwaa dwab" -- "$cur")); return 0 ;;
    --hosts | --known-hosts | --ssh-config | --preview | -o)
        _franja_files "$cur" ""; return 0 ;;
    --job | --dist | --workdir | --shared-workdir | --allow-path)
        COMPREPLY=($(compgen -d -- "$cur")); return 0 ;;
    --worker) _franja_files "$cur" ""; return 0 ;;
    --passes)
        COMPREPLY=($(compgen -W "all light denoise none albedo normal depth position emission diffuse_direct \
diffuse_indirect glossy_direct glossy_indirect transmission_direct transmission_indirect material_id crypto_material variance object_id crypto_object light_groups" -- "$cur"))
        return 0 ;;
    -j | --spp | --size | --scale | --exposure | --slab-rows | --retries | --timeout | --camera | --preview-every | \
        --monitor | --crop | --jpeg-quality | --noise-threshold | --frames | --fps | --shutter | --time-limit)
        return 0 ;;
    esac
    if [[ $cur == -* ]]; then
        local words
        if [ "$cmd" = hosts ]; then
            words=$(_franja_opts "$prog" hosts check)
        else
            words=$(_franja_opts "$prog" "$cmd")
        fi
        COMPREPLY=($(compgen -W "$words" -- "$cur"))
        return 0
    fi
    case $cmd in
    render) _franja_files "$cur" '*.@(json|gltf|glb|fbin)' ;;
    compile) _franja_files "$cur" '*.@(json|gltf|glb)' ;;
    hosts)
        [ "$i" -eq $((COMP_CWORD - 1)) ] && COMPREPLY=($(compgen -W "check list clean" -- "$cur")) ;;
    stitch) COMPREPLY=($(compgen -d -- "$cur")) ;;
    help) COMPREPLY=($(compgen -W "render compile stitch hosts deploy" -- "$cur")) ;;
    esac
    return 0
}

_franja_worker()
{
    local cur=${COMP_WORDS[COMP_CWORD]} prev=""
    [ "$COMP_CWORD" -gt 0 ] && prev=${COMP_WORDS[COMP_CWORD-1]}
    COMPREPLY=()
    case $prev in
    --scene) _franja_files "$cur" '*.@(json|fbin)'; return 0 ;;
    -o) _franja_files "$cur" ""; return 0 ;;
    --format) COMPREPLY=($(compgen -W "pf ppm16 ppm8" -- "$cur")); return 0 ;;
    --rows | --spp | --size) return 0 ;;
    esac
    COMPREPLY=($(compgen -W "$(_franja_opts "${COMP_WORDS[0]}")" -- "$cur"))
    return 0
}

shopt -s extglob
complete -F _franja franja
complete -F _franja_worker franja-worker
